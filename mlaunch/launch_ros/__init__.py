"""The top-level ``launch_ros`` namespace inside mlaunch.

``import launch_ros`` then ``launch_ros.actions.Node(...)`` works as with ROS 2: the submodules
load on first attribute access, so ``import launch_ros`` alone stays cheap.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

_SUBMODULES = (
    "actions",
    "descriptions",
    "event_handlers",
    "events",
    "parameter_descriptions",
    "substitutions",
    "utilities",
)


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'launch_ros' (mlaunch) has no attribute {name!r}")


def get_default_launch_description(*, prefix_output_with_name: bool = False) -> Any:
    """launch_ros's default description adds ROS logging setup; mlaunch needs none of it."""
    from mlaunch.launch.launch_description import LaunchDescription

    return LaunchDescription([])


__all__ = [
    "actions",
    "descriptions",
    "event_handlers",
    "events",
    "get_default_launch_description",
    "substitutions",
]
