"""mlaunch: a fast, trustworthy ROS 2 launcher.

The ROS 2 launch names are available from here too (``from mlaunch import Node,
LaunchDescription``), loaded on first use so that ``import mlaunch`` stays cheap for the CLI.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

__version__ = "0.1.0"

_MODULES = (
    "mlaunch.launch.actions",
    "mlaunch.launch.substitutions",
    "mlaunch.launch.conditions",
    "mlaunch.launch.event_handlers",
    "mlaunch.launch.launch_description_sources",
    "mlaunch.launch_ros.actions",
    "mlaunch.launch_ros.substitutions",
    "mlaunch.launch_ros.parameter_descriptions",
)


def __getattr__(name: str) -> Any:
    # Only the ROS class names live here; a lowercase name is a submodule (``from mlaunch import
    # frontends``), which Python imports itself once this raises.
    if not name[:1].isupper():
        raise AttributeError(name)
    for module_name in _MODULES:
        module = importlib.import_module(module_name)
        if name in getattr(module, "__all__", ()) or hasattr(module, name):
            value = getattr(module, name)
            globals()[name] = value
            return value
    raise AttributeError(f"module 'mlaunch' has no attribute {name!r}")
