"""``launch_ros.descriptions``: what a launch file describes for launch_ros to use: parameters,
params files and parameter values (``launch_ros.parameter_descriptions``), and composable
nodes (``ComposableLifecycleNode``: newer than Jazzy, launch_ros 0.29.3).

This package only gathers the names (``mlaunch.launch.gathering``).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch_ros.descriptions.composable_lifecycle_node import (
        ComposableLifecycleNode,
    )
    from mlaunch.launch_ros.descriptions.composable_node import ComposableNode
    from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile, ParameterValue

_gathered = Gathered(
    globals(),
    {
        "ComposableLifecycleNode": ".composable_lifecycle_node",
        "ComposableNode": ".composable_node",
        "Parameter": "mlaunch.launch_ros.parameter_descriptions",
        "ParameterFile": "mlaunch.launch_ros.parameter_descriptions",
        "ParameterValue": "mlaunch.launch_ros.parameter_descriptions",
    },
    submodules=("composable_lifecycle_node", "composable_node"),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "ComposableLifecycleNode",
    "ComposableNode",
    "Parameter",
    "ParameterFile",
    "ParameterValue",
]
