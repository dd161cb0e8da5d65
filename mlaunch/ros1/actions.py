"""The actions a roslaunch file adds to mlaunch's ROS 2 ones where roslaunch's rules differ.

An ``<include>`` of a roslaunch file reads roslaunch XML whatever the suffix; an untyped
``<param value>`` with substitutions is typed by roslaunch's rule; a node's ``args`` with
substitutions is substituted first, then split like a shell.
"""

from __future__ import annotations

import os
import shlex
from typing import TYPE_CHECKING, Any

from mlaunch.launch.action import Action
from mlaunch.launch.launch_description_sources.any_launch_description_source import (
    AnyLaunchDescriptionSource,
)
from mlaunch.launch.substitution import TextSubstitution, normalize, perform_substitutions
from mlaunch.launch_ros import params
from mlaunch.launch_ros.actions.node import Node
from mlaunch.launch_ros.actions.set_parameter import SetParameter
from mlaunch.launch_ros.parameter_descriptions import ParameterValue
from mlaunch.plan.errors import MlaunchError
from mlaunch.ros1 import config
from mlaunch.ros1.model import rel_origin
from mlaunch.ros1.params import ros2_value
from mlaunch.ros1.server import SERVER_KEY, Server, flat
from mlaunch.ros1.values import convert_value

if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch_ros.actions.node import NodeCommand, NodeNames


class RoslaunchSource(AnyLaunchDescriptionSource):
    """A file a roslaunch file includes: roslaunch XML whatever its suffix, as roslaunch reads
    it (ROS 1 packages name their fragments ``*.launch.xml``)."""

    format_hint = "roslaunch"


class RoslaunchValue(ParameterValue):
    """An untyped ``<param value>`` with substitutions, typed as roslaunch types it: int,
    float, bool (true/false, any case), else text (``[*]`` stays text)."""

    def evaluate(self, context: LaunchContext) -> Any:
        text = perform_substitutions(context, self._value)
        self._evaluated = convert_value(text.strip(), "auto")
        return self._evaluated


class RoslaunchNode(Node):
    """A node of a roslaunch file run on ROS 2.

    ``shell_args`` (``args`` with substitutions): substituted first, then split like a shell,
    as roslaunch does (an argument that substitutes to nothing disappears). Its globals come
    from the file's parameter server by ROS 1's name rules (``ros1.server``), before its own
    parameters (``own_names``: those the mapping gave it, which win).
    """

    def __init__(self, *, shell_args: Any = None, ros1_package: str = "", **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.shell_args = None if shell_args is None else normalize(shell_args)
        self.ros1_package = ros1_package

    def node_command(self, context: LaunchContext, *, remote: bool = False) -> NodeCommand:
        if self.shell_args is not None:
            text = perform_substitutions(context, self.shell_args)
            try:
                words = shlex.split(text)
            except ValueError as e:
                raise MlaunchError(f"node args {text!r} cannot be split like a shell: {e}")
            self.arguments = [(TextSubstitution(text=w),) for w in words]
        return super().node_command(context, remote=remote)

    def _global_parameter_arguments(self, ctx: LaunchContext) -> list[str]:
        out = super()._global_parameter_arguments(ctx)
        found = self.from_server(ctx)
        if found is None:
            return out
        for name, value in self.holdable(ctx, flat(found[1])).items():
            out += ["-p", rule(name, value)]
        return out

    def _parameter_arguments(
        self, context: LaunchContext, names: NodeNames
    ) -> tuple[list[str], tuple[str, ...]]:
        found = self.from_server(context)
        if found is None:
            return super()._parameter_arguments(context, names)
        mapped = self.parameters
        own = self.holdable(context, flat(found[0]))
        self.parameters = params.normalize_parameters([own]) if own else ()
        try:
            return super()._parameter_arguments(context, names)
        finally:
            self.parameters = mapped

    def _remap_arguments(self, ctx: LaunchContext) -> list[tuple[str, str]]:
        """roslaunch's remaps: one per ``from``, the node's own (or a later one) replacing its
        scope's (rcl would apply the first of two)."""
        out: list[tuple[str, str]] = []
        for src, dst in super()._remap_arguments(ctx):
            out = [r for r in out if r[0] != src]
            out.append((src, dst))
        return out

    def from_server(self, ctx: LaunchContext) -> tuple[dict[str, Any], dict[str, Any]] | None:
        """(own, others): the parameters the file's parameter server holds for this node."""
        server = server_for(ctx, _file(self.origin))
        if server is None:
            return None
        names = self._names(ctx)
        return server.parameters_of(names.name, names.namespace or "/", self.ros1_package)

    def holdable(self, context: LaunchContext, found: dict[str, Any]) -> dict[str, Any]:
        """The values a ROS 2 parameter can hold; each other one is a warning."""
        out: dict[str, Any] = {}
        for name, value in found.items():
            held, problem = ros2_value(value)
            if problem is not None:
                where = rel_origin(self.origin)
                context.planner.warn(f"{where}: parameter {name}: {problem}; it is not set")
                continue
            out[name] = held
        return out


def rule(name: str, value: Any) -> str:
    """``name:=value`` as a SetParameter writes it, text that rcl or YAML would read as
    something else quoted (roslaunch's ``"1e3"`` and ``""`` stay text)."""
    if isinstance(value, str) and (
        not value
        or "\n" in value
        or not params.rcl_reads_as_text(value)
        or not isinstance(_yaml(value), str)
    ):
        dumped = params.parameter_rule(name, value)
        return dumped.removesuffix("\n...\n").rstrip("\n")
    return params.global_parameter_rule(name, value)


def _yaml(text: str) -> Any:
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        return load_yaml(text)
    except yaml.YAMLError:
        return None


class MappingWarning(Action):
    """A warning about the ROS 1 -> ROS 2 mapping, reported where the file is resolved."""

    def __init__(self, message: str, origin: str, condition: Any = None) -> None:
        super().__init__(condition=condition)
        self.message = message
        self.origin = origin

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        planner.warn(f"{rel_origin(self.origin)}: {self.message}")

    def describe_short(self) -> str:
        return f"warning: {self.message}"


class LoadParameterServer(Action):
    """First action of a roslaunch file run on ROS 2: the file resolved as roslaunch resolves
    it, whose parameter server the file's nodes take their globals from (``ros1.server``).

    One server covers a file and everything it includes; a file that an enclosing roslaunch
    file already covers adds nothing. Where roslaunch itself would refuse the file, the nodes
    keep the globals of their scopes (SetParameter), with a warning saying why.
    """

    def __init__(self, path: str, arg_names: list[str]) -> None:
        super().__init__()
        self.path = path
        self.arg_names = arg_names

    def execute(self, context: LaunchContext) -> None:
        servers: dict[str, Server | None] | None = context.locals.get(SERVER_KEY)
        if servers is None:
            servers = {}
            context.extend_globals({SERVER_KEY: servers})
        if server_for(context, self.path) is not None or self.path in servers:
            return
        configs = context.launch_configurations
        args = {n: configs[n] for n in self.arg_names if isinstance(configs.get(n), str)}
        from mlaunch.ros import packages

        index = packages.for_context(context)
        try:
            environ = dict(context.environment)
            pushed = configs.get("ros_namespace")
            if isinstance(pushed, str) and pushed:  # a ROS 2 includer's namespace is its root
                environ["ROS_NAMESPACE"] = pushed
            found = config.load(self.path, args, environ=environ, index=index)
        except MlaunchError as e:
            context.planner.warn(
                f"{rel_origin(self.path)}: roslaunch would refuse this file ({e}); its global"
                " parameters go to the nodes of their scopes instead of by ROS 1's name rules"
            )
            servers[self.path] = None
            return
        servers[self.path] = Server.of(found)

    def describe_short(self) -> str:
        return "ROS 1 parameter server"


def server_for(context: LaunchContext, path: str) -> Server | None:
    """The parameter server that covers the roslaunch file at ``path``, if any."""
    servers: dict[str, Server | None] = context.locals.get(SERVER_KEY) or {}
    real = os.path.realpath(path)
    for server in servers.values():
        if server is not None and real in server.config.files:
            return server
    return None


class GlobalParameter(SetParameter):
    """A roslaunch global parameter: given by the parameter server when its file has one,
    else a SetParameter for the nodes of its scope."""

    keep_in_scope = True  # ROS 1 global parameters belong to their group

    def execute(self, context: LaunchContext) -> None:
        if server_for(context, _file(self.origin)) is None:
            super().execute(context)


class ScopeNote(MappingWarning):
    """A warning about the scope mapping of globals: moot where a parameter server maps them."""

    def execute(self, context: LaunchContext) -> None:
        if server_for(context, _file(self.origin)) is None:
            super().execute(context)


def _file(origin: str) -> str:
    return origin.rsplit(":", 1)[0] if origin else ""
