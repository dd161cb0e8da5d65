"""``launch_ros.actions``: the actions of launch_ros (nodes, containers, lifecycle transitions, and
those that set ROS scope state: namespace, global parameters, remaps, log folder).

Each action lives in its own module, named as upstream's; this package only gathers the names,
each module loaded when one of its names is first asked for (``mlaunch.launch.gathering``). The
scope state and the naming rules are mlaunch.launch_ros.scope's. Importing this package
registers the in-process xacro for ``Command(['xacro ', ...])``, as it always did.
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered
from mlaunch.launch_ros import xacro as _xacro

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch_ros.actions.composable_node_container import ComposableNodeContainer
    from mlaunch.launch_ros.actions.lifecycle_node import LifecycleNode
    from mlaunch.launch_ros.actions.lifecycle_transition import LifecycleTransition
    from mlaunch.launch_ros.actions.load_composable_nodes import LoadComposableNodes
    from mlaunch.launch_ros.actions.node import Node, NodeCommand, NodeNames
    from mlaunch.launch_ros.actions.push_ros_namespace import PushROSNamespace, PushRosNamespace
    from mlaunch.launch_ros.actions.ros_timer import ROSTimer, RosTimer
    from mlaunch.launch_ros.actions.set_parameter import SetParameter, with_use_sim_time
    from mlaunch.launch_ros.actions.set_parameters_from_file import SetParametersFromFile
    from mlaunch.launch_ros.actions.set_remap import SetRemap
    from mlaunch.launch_ros.actions.set_ros_log_dir import SetROSLogDir, SetRosLogDir
    from mlaunch.launch_ros.actions.set_use_sim_time import SetUseSimTime
    from mlaunch.launch_ros.scope import (
        make_namespace_absolute,
        namespace_problem,
        node_name_problem,
        prefix_namespace,
    )

_gathered = Gathered(
    globals(),
    {
        "ComposableNodeContainer": ".composable_node_container",
        "LifecycleNode": ".lifecycle_node",
        "LifecycleTransition": ".lifecycle_transition",
        "LoadComposableNodes": ".load_composable_nodes",
        "Node": ".node",
        "NodeCommand": ".node",
        "NodeNames": ".node",
        "PushROSNamespace": ".push_ros_namespace",
        "PushRosNamespace": ".push_ros_namespace",
        "ROSTimer": ".ros_timer",
        "RosTimer": ".ros_timer",
        "SetParameter": ".set_parameter",
        "SetParametersFromFile": ".set_parameters_from_file",
        "SetROSLogDir": ".set_ros_log_dir",
        "SetRosLogDir": ".set_ros_log_dir",
        "SetRemap": ".set_remap",
        "SetUseSimTime": ".set_use_sim_time",
        "make_namespace_absolute": "mlaunch.launch_ros.scope",
        "namespace_problem": "mlaunch.launch_ros.scope",
        "node_name_problem": "mlaunch.launch_ros.scope",
        "prefix_namespace": "mlaunch.launch_ros.scope",
        "with_use_sim_time": ".set_parameter",
    },
    submodules=(
        "composable_node_container",
        "lifecycle_node",
        "lifecycle_transition",
        "load_composable_nodes",
        "node",
        "push_ros_namespace",
        "ros_timer",
        "set_parameter",
        "set_parameters_from_file",
        "set_remap",
        "set_ros_log_dir",
        "set_use_sim_time",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

_xacro.register()

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
    "SetRosLogDir",
    "SetUseSimTime",
    "make_namespace_absolute",
    "namespace_problem",
    "node_name_problem",
    "prefix_namespace",
    "with_use_sim_time",
]
