"""``Node`` and ``LifecycleNode``: an executable of a package, with launch_ros's command line.

A Node resolves to the command line launch_ros gives it, in launch_ros's order::

    <exe> <arguments...> [--ros-args <ros_arguments...>] --ros-args
        [-r __node:=<name>] [-r __ns:=<namespace>]
        (-p <name>:=<value> | --params-file <path>)...     globals of SetParameter(s)FromFile
        (--params-file <file per dict> | --params-file <path> | -p <name>:=<value>)...
        (-r <from>:=<to>)...                                SetRemap globals, then remappings

Resolving builds a NodeCommand and hands what the process needs to ExecuteProcess.process_spec;
nothing of a resolution is kept on the action except what launch_ros exposes of the last one
(``node_name``, ``expanded_remapping_rules``, ``cmd``), which resolving never reads back."""

from __future__ import annotations

import os
from collections.abc import Iterable

from mlaunch import standins
from mlaunch.launch.actions.execute_process import ExecuteProcess
from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    TextSubstitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch.substitutions.local_substitution import LocalSubstitution
from mlaunch.launch_ros import params
from mlaunch.launch_ros.descriptions.composable_node import remap_rules as _remap_rules
from mlaunch.launch_ros.parameter_descriptions import ParameterFile
from mlaunch.launch_ros.scope import (
    global_params,
    namespace_problem,
    node_name_problem,
    params_file_origin,
    prefix_namespace,
    ros_remaps,
)
from mlaunch.launch_ros.substitutions.executable_in_package import ExecutableInPackage
from mlaunch.plan.errors import LaunchFileError, MlaunchError, SubstitutionFailure, did_you_mean
from mlaunch.plan.steps import NodeInfo, ProcessSpec
from mlaunch.plan.value import Value
from mlaunch.ros import packages
from mlaunch.ros.packages import PackageNotFoundError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


Subs = tuple[Substitution, ...]


# launch_ros's key for the count of full node names in the context globals.
NODE_NAMES_KEY = "unique_ros_node_names"


def node_name_counts(ctx: LaunchContext) -> dict[str, int]:
    """How many nodes of this run got each full name: launch_ros's count in the context's
    globals, shared by Nodes and the components loaded into containers."""
    counts: dict[str, int] | None = ctx.locals.get(NODE_NAMES_KEY)
    if counts is None:
        counts = {}
        ctx.extend_globals({NODE_NAMES_KEY: counts})
    return counts


def same_name_warning(count: int, name: str) -> str:
    """launch_ros's words for a node name given ``count`` times in one launch."""
    return (
        f"there are now at least {count} nodes with the name {name} created within this"
        " launch context"
    )


class NodeNames(Value):
    """A node's name and namespace as resolved (None: not given, the node's own default)."""

    _fields = ("name", "namespace")
    __slots__ = _fields

    def __init__(self, name: str | None, namespace: str | None) -> None:
        self.name = name
        self.namespace = namespace

    @property
    def fully_qualified(self) -> str | None:
        if self.name is None:
            return None
        return prefix_namespace(self.namespace or "/", self.name)

    @property
    def params_key(self) -> str:
        """The params-file key: the full name when both are known, else ``/**``."""
        if self.name is not None and self.namespace is not None:
            return prefix_namespace(self.namespace, self.name) or "/**"
        return "/**"


class NodeCommand(Value):
    """What one resolution of a Node found: its names, what runs, its command line."""

    _fields = ("names", "package", "executable", "exe_argv", "standin", "argv", "temp_files")
    __slots__ = _fields

    def __init__(
        self,
        names: NodeNames,
        package: str | None,
        executable: str,
        exe_argv: list[str],
        standin: str | None,
        argv: list[str],
        temp_files: tuple[str, ...],
    ) -> None:
        self.names = names
        self.package = package
        self.executable = executable
        self.exe_argv = exe_argv  # the argv items that run the executable (or its stand-in)
        self.standin = standin  # what a stand-in replaces, or None
        self.argv = argv
        self.temp_files = temp_files  # params files to remove with the process


class RosPart(Value):
    """The command line of a node after its name and namespace, as launch_ros's
    ``_perform_substitutions`` works it out: the scope's params arguments (SetParameter,
    SetParametersFromFile), the node's own, then the remapping rules."""

    _fields = ("scope", "own", "remaps", "temp_files")
    __slots__ = _fields

    def __init__(
        self,
        scope: list[str],
        own: list[str],
        remaps: list[tuple[str, str]],
        temp_files: tuple[str, ...],
    ) -> None:
        self.scope = scope  # ["-p", "name:=value", "--params-file", path, ...]
        self.own = own
        self.remaps = remaps
        self.temp_files = temp_files  # params files to remove with the process

    @property
    def argv(self) -> list[str]:
        rules = [item for src, dst in self.remaps for item in ("-r", f"{src}:={dst}")]
        return [*self.scope, *self.own, *rules]


# launch_ros's local substitutions for the name and namespace arguments in a Node's ``cmd``.
_NAME_ARGUMENT = "ros_specific_arguments['name']"


_NAMESPACE_ARGUMENT = "ros_specific_arguments['ns']"


class Node(ExecuteProcess):
    """A ROS node: an executable of a package (or a path) with launch_ros's command line."""

    UNSPECIFIED_NODE_NAME = "<node_name_unspecified>"
    UNSPECIFIED_NODE_NAMESPACE = "<node_namespace_unspecified>"
    is_lifecycle = False

    def __init__(
        self,
        *,
        executable: SomeSubstitutionsType,
        package: SomeSubstitutionsType | None = None,
        name: SomeSubstitutionsType | None = None,
        namespace: SomeSubstitutionsType | None = None,
        exec_name: SomeSubstitutionsType | None = None,
        parameters: Any = None,
        remappings: Any = None,
        ros_arguments: Iterable[SomeSubstitutionsType] | None = None,
        arguments: Iterable[SomeSubstitutionsType] | None = None,
        **kwargs: Any,
    ) -> None:
        first: Any = executable if package is None else ExecutableInPackage(executable, package)
        super().__init__(cmd=[first], name=exec_name, **kwargs)
        self.node_executable = normalize(executable)
        self.node_package = None if package is None else normalize(package)
        self._node_name = None if name is None else normalize(name)
        self._node_namespace = None if namespace is None else normalize(namespace)
        self.parameters = () if parameters is None else params.normalize_parameters(parameters)
        self.remappings = _remap_rules(remappings)
        self.ros_arguments = (
            None if ros_arguments is None else _items(ros_arguments, "ros_arguments")
        )
        self.arguments = [] if arguments is None else _items(arguments, "arguments")
        # launch_ros's node_name and friends: the names of the last resolution (for launch-file
        # code that reads them after the node was visited; resolving itself never reads them).
        self.resolved_names: NodeNames | None = None
        # ``cmd`` as launch_ros holds it: before a resolution, up to the node's name argument.
        self._cmd += [list(a) for a in self.arguments]
        if self.ros_arguments is not None:
            self._cmd += [_text("--ros-args"), *(list(a) for a in self.ros_arguments)]
        self._cmd.append(_text("--ros-args"))
        if self._node_name is not None:
            self._cmd += [_text("-r"), [LocalSubstitution(_NAME_ARGUMENT)]]
        self._given_cmd = list(self._cmd)
        # launch_ros's record of the last resolution's params arguments ((value, is a file)) and
        # remapping rules (None: none); its unit tests read the first by its private name.
        self.__expanded_parameter_arguments: list[tuple[str, bool]] | None = None
        self.__expanded_remappings: list[tuple[str, str]] | None = None

    # --- what launch_ros exposes ------------------------------------------------------------

    @property
    def node_name(self) -> str:
        """The full node name once resolved (with launch_ros's placeholders for unknown parts)."""
        names = self.resolved_names
        if names is None:
            raise RuntimeError("cannot access 'node_name' before executing action")
        # launch_ros's rule: an unspecified namespace leaves the name relative.
        from mlaunch.launch_ros.utilities.namespace_utils import prefix_namespace as upstreams

        return (
            upstreams(
                names.namespace or self.UNSPECIFIED_NODE_NAMESPACE,
                names.name or self.UNSPECIFIED_NODE_NAME,
            )
            or ""
        )

    def is_node_name_fully_specified(self) -> bool:
        names = self.resolved_names
        return names is not None and names.name is not None and names.namespace is not None

    @property
    def expanded_node_namespace(self) -> str:
        names = self.resolved_names
        if names is None or names.namespace is None:
            return self.UNSPECIFIED_NODE_NAMESPACE
        return names.namespace

    @property
    def expanded_remapping_rules(self) -> list[tuple[str, str]] | None:
        """The remapping rules of the last resolution, SetRemap's first (None: there were none)."""
        return self.__expanded_remappings

    def _perform_substitutions(self, context: LaunchContext) -> None:
        """launch_ros's step that works out the names, the params arguments (writing the params
        files) and the remappings, without finding the executable; its unit tests call it on its
        own, then read ``node_name``, ``expanded_remapping_rules`` and ``cmd``."""
        names = self._names(context)
        self._record(names, self._ros_part(context, names))

    def _ros_part(self, context: LaunchContext, names: NodeNames) -> RosPart:
        """The command line after the name and namespace: parameters, then remappings."""
        scope = self._global_parameter_arguments(context)
        own, temp_files = self._parameter_arguments(context, names)
        remaps = self._remap_arguments(context)
        return RosPart(scope, own, remaps, temp_files)

    def _record(self, names: NodeNames, part: RosPart) -> None:
        """Keep what launch_ros exposes of a resolution: names, params arguments, remappings,
        and ``cmd`` as launch_ros holds it (the name and namespace as its local substitutions)."""
        self.resolved_names = names
        self.__expanded_parameter_arguments = [
            *((value, True) for flag, value in _pairs(part.scope) if flag == "--params-file"),
            *((value, flag == "--params-file") for flag, value in _pairs(part.own)),
        ]
        self.__expanded_remappings = list(part.remaps) if part.remaps else None
        cmd = list(self._given_cmd)
        if names.namespace is not None:
            cmd += [_text("-r"), [LocalSubstitution(_NAMESPACE_ARGUMENT)]]
        cmd += [_text(item) for item in part.argv]
        self._cmd = cmd

    # --- resolving ------------------------------------------------------------------------------

    def node_command(self, context: LaunchContext, *, remote: bool = False) -> NodeCommand:
        """The node's names and launch_ros's command line for it, in the context's context.

        ``remote``: the node runs on another computer (mlaunch.machines), which finds the
        package's executable itself.
        """
        names = self._names(context)
        package, executable, exe_argv, standin = self._executable(context, remote)
        argv = [*exe_argv, *(perform_substitutions(context, a) for a in self.arguments)]
        if self.ros_arguments is not None:
            argv += ["--ros-args", *(perform_substitutions(context, a) for a in self.ros_arguments)]
        argv.append("--ros-args")
        if names.name is not None:
            argv += ["-r", f"__node:={names.name}"]
        if names.namespace is not None:
            argv += ["-r", f"__ns:={names.namespace}"]
        part = self._ros_part(context, names)
        argv += part.argv
        planner = getattr(context, "planner", None)
        options = None if planner is None else planner.options
        for level in getattr(options, "log_levels", ()):
            argv += ["--log-level", level]  # mlaunch --log-level: every ROS process
        self._record(names, part)
        return NodeCommand(names, package, executable, exe_argv, standin, argv, part.temp_files)

    def command(self, context: LaunchContext) -> list[str]:
        return self.node_command(context).argv

    def build_spec(self, context: LaunchContext) -> ProcessSpec:
        machine = self._machine(context)
        found = self.node_command(context, remote=self._runs_there(context, machine))
        info = NodeInfo(
            name=found.names.name,
            namespace=found.names.namespace or "/",
            package=found.package,
            executable=found.executable,
            lifecycle=self.is_lifecycle,
            autostart=bool(getattr(self, "autostart", False)),
        )
        spec = self.process_spec(
            context,
            found.argv,
            node=info,
            # A stand-in is labelled as the program it replaces (unless a launch prefix leads).
            replaced_label=None if found.standin is None else os.path.basename(found.executable),
            standin=found.standin,
            temp_files=found.temp_files,
            machine=machine,
        )
        self._track_name(context, found.names)
        return spec

    # --- pieces -------------------------------------------------------------------------------

    def _names(self, ctx: LaunchContext) -> NodeNames:
        name = None
        if self._node_name is not None:
            name = perform_substitutions(ctx, self._node_name)
            problem = node_name_problem(name)
            if problem is not None:
                raise MlaunchError(f"node name {name!r} is invalid: {problem}")
        given = None
        if self._node_namespace is not None:
            given = perform_substitutions(ctx, self._node_namespace)
        pushed = ctx.launch_configurations.get("ros_namespace")
        namespace = prefix_namespace(pushed, given)
        if namespace is not None:
            problem = namespace_problem(namespace)
            if problem is not None:
                detail = f"namespace={given!r}" + (f", pushed {pushed!r}" if pushed else "")
                raise MlaunchError(f"node namespace {namespace!r} ({detail}) is invalid: {problem}")
        return NodeNames(name, namespace)

    def _executable(
        self, context: LaunchContext, remote: bool
    ) -> tuple[str | None, str, list[str], str | None]:
        """(package, executable, argv items that run it, what a stand-in replaces)."""
        planner = context.planner
        executable = perform_substitutions(context, self.node_executable)
        if self.node_package is None:
            return None, executable, [executable], None
        package = perform_substitutions(context, self.node_package)
        index = packages.for_context(context)
        if remote:
            # Found on that computer (mlaunch.parts.agent looks the package up there); this
            # computer's path is only a hint, and there are no stand-ins on other computers.
            return package, executable, [remote_executable(index, package, executable)], None
        try:
            if index.installed(package) is not None:
                return package, executable, [index.executable(package, executable)], None
            if planner.options.standins:
                replacement = standins.standin_for_package(package, executable)
                if replacement is not None:
                    return package, executable, list(replacement), f"{package}/{executable}"
            raise _not_installed(index, package, executable, planner.options.standins)
        except PackageNotFoundError as error:
            if not planner.options.dry_run:
                raise
            # --print on a laptop where the workspace is not built: the plan, with the gap said.
            shown = f"{package}/{executable}"
            planner.warn(f"{self.origin}: {error}; shown as {shown!r}, a run refuses to start")
            return package, executable, [shown], None

    def _global_parameter_arguments(self, ctx: LaunchContext) -> list[str]:
        out: list[str] = []
        for entry in global_params(ctx):
            if isinstance(entry, (tuple, list)) and len(entry) == 2:
                out += ["-p", params.global_parameter_rule(str(entry[0]), entry[1])]
                continue
            path = os.path.abspath(str(entry))
            if not os.path.isfile(path):
                raise SubstitutionFailure(
                    f"global parameters file {path!r} does not exist"
                    f"{params_file_origin(ctx, str(entry))}"
                )
            out += ["--params-file", path]
        return out

    def _parameter_arguments(
        self, context: LaunchContext, names: NodeNames
    ) -> tuple[list[str], tuple[str, ...]]:
        """The node's own params arguments and the temporary files to remove (if mlaunch must)."""
        # A stand-in context of a unit test (launch_configurations only) has no planner.
        planner = getattr(context, "planner", None)
        if not self.parameters:
            return [], ()
        temp_dir = None if planner is None else planner.options.temp_dir
        private = None
        if planner is not None and temp_dir is None and _writes_files(self.parameters):
            # No run directory to write into: a private one, removed with the process's files.
            import tempfile

            temp_dir = private = tempfile.mkdtemp(prefix="mlaunch-params-")

        def warn(message: str) -> None:
            if planner is not None:
                planner.warn(f"{self.origin}: {message}")
            else:
                from mlaunch.launch.logging import get_logger

                get_logger("launch_ros").warning(f"{self.origin}: {message}")

        arguments = params.parameter_arguments(
            context,
            self.parameters,
            node_key=names.params_key,
            temp_dir=temp_dir,
            warn=warn,
        )
        argv = [item for a in arguments for item in (a.flag, a.value)]
        if private is None:
            return argv, ()
        return argv, (*(a.value for a in arguments if a.written), private)

    def _remap_arguments(self, ctx: LaunchContext) -> list[tuple[str, str]]:
        own = [
            (perform_substitutions(ctx, src), perform_substitutions(ctx, dst))
            for src, dst in self.remappings
        ]
        return [*ros_remaps(ctx), *own]

    def _track_name(self, ctx: LaunchContext, names: NodeNames) -> None:
        """Warn when a second node gets the same full name (launch_ros's per-launch count).

        The count lives in the run's context globals, as launch_ros keeps it. As there, only a
        node whose name and namespace are both given (or pushed) is counted: launch_ros leaves
        a node without either out of the count, and so out of the warning.
        """
        fqn = names.fully_qualified
        if fqn is None or names.namespace is None:
            return
        counts = node_name_counts(ctx)
        counts[fqn] = counts.get(fqn, 0) + 1
        if counts[fqn] > 1:
            ctx.warn(f"{self.origin}: {same_name_warning(counts[fqn], fqn)}")

    def describe_short(self) -> str:
        parts = []
        if self.node_package is not None:
            parts.append(f"package={describe(self.node_package)}")
        parts.append(f"executable={describe(self.node_executable)}")
        if self._node_name is not None:
            parts.append(f"name={describe(self._node_name)}")
        if self._node_namespace is not None:
            parts.append(f"namespace={describe(self._node_namespace)}")
        return f"{type(self).__name__}({', '.join(parts)})"


def remote_executable(index: Any, package: str, executable: str) -> str:
    """A remote node's program: this computer's path when installed here, else ``PKG/EXE``."""
    if index.installed(package) is not None:
        try:
            return str(index.executable(package, executable))
        except MlaunchError:
            pass
    return f"{package}/{executable}"


def _writes_files(entries: Iterable[Any]) -> bool:
    return any(
        isinstance(e, dict) or (isinstance(e, ParameterFile) and e.allow_substs is not False)
        for e in entries
    )


def _not_installed(
    index: packages.PackageIndex, package: str, executable: str, standins_on: bool
) -> PackageNotFoundError:
    """The error for a package no ament prefix holds: missing, or only a checkout."""
    hint = ""
    if (package, executable) in standins.PACKAGE_EXECUTABLES:
        if not standins_on:
            hint = " (mlaunch has a stand-in for it: run without --no-standins)"
        elif not standins.rclpy_available():
            hint = " (mlaunch's stand-in for it needs rclpy: pip install 'mlaunch[ros]')"
        elif (need := standins.unmet_need(package, executable)) is not None:
            hint = f" (mlaunch's stand-in for it needs {need}: ./scripts/setup builds it)"
    source = index.source(package)
    if source is None:
        standin_executables = [e for p, e in standins.PACKAGE_EXECUTABLES if p == package]
        if standin_executables and standins_on and not hint:
            # The package is one mlaunch stands in for: the executable is what is wrong.
            return PackageNotFoundError(
                f"executable {executable!r} not found in package {package!r}"
                f"{did_you_mean(executable, standin_executables)}: mlaunch's stand-in for the"
                f" package runs {', '.join(map(repr, standin_executables))} (the package itself"
                f" is not installed: {index.searched()})"
            )
        known = {*index.all_packages(), *(p for p, _ in standins.PACKAGE_EXECUTABLES)}
        return PackageNotFoundError(
            f"package {package!r} not found{did_you_mean(package, known)}, wanted for executable"
            f" {executable!r} ({index.searched()}){hint}"
        )
    return PackageNotFoundError(
        f"package {package!r} is only a source package at {source.share_directory!r} (not"
        f" built): its executable {executable!r} exists once it is built and installed (colcon"
        f" build, then source install/setup.bash){hint}"
    )


def _text(item: str) -> list[Substitution]:
    """One item of launch_ros's ``cmd``: its text as a substitution list."""
    return [TextSubstitution(text=item)]


def _pairs(argv: list[str]) -> list[tuple[str, str]]:
    """``[flag, value, flag, value, ...]`` as pairs."""
    return list(zip(argv[::2], argv[1::2], strict=True))


def _items(values: Any, what: str) -> list[Subs]:
    if isinstance(values, (str, Substitution)):
        raise LaunchFileError(
            f"{what} must be a list of arguments, got {type(values).__name__} {values!r:.80}"
            f" (write {what}=[...])"
        )
    return [normalize(v) for v in values]


__all__ = ["Node", "NodeCommand", "NodeNames"]
