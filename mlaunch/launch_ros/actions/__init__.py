"""``launch_ros.actions``: the actions that set ROS scope state (namespace, global parameters,
remaps, log folder), and Node and LifecycleNode (mlaunch.launch_ros.node) under their ROS 2 names.

The scope state and the naming rules are mlaunch.launch_ros.scope's. Importing this module
registers the in-process xacro for ``Command(['xacro ', ...])``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping

from mlaunch.launch.actions import Action, LaunchDescription
from mlaunch.launch.substitutions import (
    SomeSubstitutionsType,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch_ros import params
from mlaunch.launch_ros import xacro as _xacro
from mlaunch.launch_ros.node import LifecycleNode, Node, NodeCommand, NodeNames
from mlaunch.launch_ros.parameter_descriptions import normalize_typed, perform_typed
from mlaunch.launch_ros.scope import (
    add_global_params,
    add_global_remap,
    make_namespace_absolute,
    namespace_problem,
    node_name_problem,
    note_params_file_origin,
    prefix_namespace,
)
from mlaunch.plan.errors import SubstitutionFailure
from mlaunch.plan.steps import SIM_TIME_STATE

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.actions import LaunchDescriptionEntity
    from mlaunch.launch.launch_context import LaunchContext

_xacro.register()


def with_use_sim_time(description: LaunchDescriptionEntity, value: bool) -> LaunchDescription:
    """``mlaunch --use-sim-time``: the description opened by ``SetParameter('use_sim_time', ...)``.

    An explicit action placed before the description, so ``use_sim_time`` is the first global
    parameter of every node (a node's own parameters can still override it, as they override
    any SetParameter).
    """
    first = SetParameter("use_sim_time", bool(value))
    first.origin = "--use-sim-time"
    return LaunchDescription([first, description])


class PushROSNamespace(Action):
    """Push a ROS namespace: nodes after it (in this scope) live under it; relative ones nest."""

    def __init__(self, namespace: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.namespace = normalize(namespace)

    def execute(self, context: LaunchContext) -> None:
        pushed = perform_substitutions(context, self.namespace)
        previous = context.launch_configurations.get("ros_namespace")
        combined = prefix_namespace(previous, pushed)
        assert combined is not None
        problem = namespace_problem(combined)
        if problem is not None:
            raise SubstitutionFailure(
                f"the resulting namespace {combined!r} is invalid: {problem}"
                f" [previous_namespace={previous!r}, pushed_namespace={pushed!r}]"
            )
        context.launch_configurations["ros_namespace"] = combined

    def describe_short(self) -> str:
        return f"PushROSNamespace({describe(self.namespace)})"


PushRosNamespace = PushROSNamespace


class SetParameter(Action):
    """A global parameter for every node after it in this scope (``-p name:=value``)."""

    # mlaunch's: True keeps it inside a scoped group even without --scoped-parameters.
    keep_in_scope = False

    def __init__(self, name: SomeSubstitutionsType, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.param_dict = params.normalize_dict({normalize(name): value})
        self._given = (name, value)

    @property
    def name(self) -> Any:
        """launch_ros's: the parameter's name, normalized (a tuple of substitutions)."""
        return next(iter(self._public_dict()))

    @property
    def value(self) -> Any:
        """launch_ros's: the value in launch_ros's normalized shape (see
        launch_ros.utilities.normalize_parameters)."""
        return next(iter(self._public_dict().values()))

    def _public_dict(self) -> dict[Any, Any]:
        from mlaunch.launch_ros.utilities.normalize_parameters import normalize_parameter_dict

        name, value = self._given
        return normalize_parameter_dict({normalize(name): value})

    def execute(self, context: LaunchContext) -> None:
        entries = tuple(params.evaluate_dict(context, self.param_dict).items())
        add_global_params(context, self, entries)

    def describe_short(self) -> str:
        (name,) = self.param_dict
        return f"SetParameter({describe(name)})"


class SetParametersFromFile(Action):
    """A params file for every node after it in this scope (``--params-file``)."""

    def __init__(self, filename: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.filename = normalize(filename)

    def execute(self, context: LaunchContext) -> None:
        # As given, as launch_ros keeps it: a node after it looks the file up (relative to the
        # working directory) and, when it is missing, names this line.
        filename = perform_substitutions(context, self.filename)
        note_params_file_origin(context, filename, self.origin)
        add_global_params(context, self, (filename,))

    def describe_short(self) -> str:
        return f"SetParametersFromFile({describe(self.filename)})"


class SetRemap(Action):
    """A remapping for every node after it in this scope (``-r from:=to``)."""

    def __init__(self, src: SomeSubstitutionsType, dst: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.src = normalize(src)
        self.dst = normalize(dst)

    # mlaunch's: True keeps it inside a scoped group even without --scoped-parameters.
    keep_in_scope = False

    def execute(self, context: LaunchContext) -> None:
        rule = (perform_substitutions(context, self.src), perform_substitutions(context, self.dst))
        add_global_remap(context, self, rule)

    def describe_short(self) -> str:
        return f"SetRemap({describe(self.src)} -> {describe(self.dst)})"


class SetUseSimTime(Action):
    """``use_sim_time`` of launch's own ROS clock (ROSTimer), as in Jazzy.

    As in launch_ros (Jazzy), this does NOT set use_sim_time on the nodes; the value is kept
    in the launch configuration ``ros_use_sim_time`` and a warning points at the ways that do:
    ``SetParameter('use_sim_time', True)`` or ``mlaunch --use-sim-time``.
    """

    def __init__(self, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.value = normalize_typed(value, bool)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        value = bool(perform_typed(context, self.value, bool))
        context.launch_configurations["ros_use_sim_time"] = value
        # launch's own ROS node is one per launch: not scoped (a ROSTimer reads it, run time).
        context.run_state[SIM_TIME_STATE] = value
        planner.warn(
            f"{self.origin}: SetUseSimTime({value}) sets use_sim_time only for launch's own ROS"
            " clock, not for the nodes (as in ROS 2 Jazzy); use SetParameter('use_sim_time',"
            f" {value}) or mlaunch --use-sim-time for the nodes"
        )


class SetROSLogDir(Action):
    """``ROS_LOG_DIR`` for processes started after it: absolute, or joined to the current one."""

    def __init__(self, new_log_dir: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.log_dir = normalize(new_log_dir)

    def execute(self, context: LaunchContext) -> None:
        new = perform_substitutions(context, self.log_dir)
        context.environment["ROS_LOG_DIR"] = os.path.join(ros_log_dir(context.environment), new)


SetRosLogDir = SetROSLogDir


def ros_log_dir(environ: Mapping[str, str]) -> str:
    """rcl's logging directory: ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log."""
    home = environ.get("HOME") or os.path.expanduser("~")
    explicit = environ.get("ROS_LOG_DIR")
    if explicit:
        return explicit.replace("~", home, 1) if explicit.startswith("~") else explicit
    ros_home = environ.get("ROS_HOME")
    if ros_home:
        ros_home = ros_home.replace("~", home, 1) if ros_home.startswith("~") else ros_home
        return os.path.join(ros_home, "log")
    return os.path.join(home, ".ros", "log")


# Actions in modules that import this one, loaded on first use: name -> module.
_LAZY = {
    "ComposableNodeContainer": "mlaunch.launch_ros.composition",
    "LoadComposableNodes": "mlaunch.launch_ros.composition",
    "LifecycleTransition": "mlaunch.launch_ros.actions.lifecycle_transition",
    "ROSTimer": "mlaunch.launch_ros.actions.ros_timer",
    "RosTimer": "mlaunch.launch_ros.actions.ros_timer",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "ComposableNodeContainer",
    "LifecycleNode",
    "LifecycleTransition",
    "LoadComposableNodes",
    "Node",
    "NodeCommand",
    "NodeNames",
    "PushROSNamespace",
    "PushRosNamespace",
    "ROSTimer",
    "RosTimer",
    "SetParameter",
    "SetParametersFromFile",
    "SetROSLogDir",
    "SetRemap",
    "SetUseSimTime",
    "make_namespace_absolute",
    "namespace_problem",
    "node_name_problem",
    "prefix_namespace",
    "with_use_sim_time",
]
