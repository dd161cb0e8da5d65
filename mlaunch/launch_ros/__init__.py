"""The top-level ``launch_ros`` namespace (and ``launch_ros.utilities``) inside mlaunch.

``import launch_ros`` then ``launch_ros.actions.Node(...)`` works as with ROS 2: the submodules
load on first attribute access, so ``import launch_ros`` alone stays cheap.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch_ros.params import evaluate_dict as evaluate_parameter_dict
    from mlaunch.launch_ros.params import normalize_dict as normalize_parameter_dict
    from mlaunch.launch_ros.params import normalize_parameters
    from mlaunch.launch_ros.scope import make_namespace_absolute, prefix_namespace

# launch_ros.utilities names -> (module, attribute): loaded on first use so that importing
# ``launch_ros.substitutions`` alone does not load the Node machinery.
_NAMES: dict[str, tuple[str, str]] = {
    "make_namespace_absolute": ("mlaunch.launch_ros.scope", "make_namespace_absolute"),
    "prefix_namespace": ("mlaunch.launch_ros.scope", "prefix_namespace"),
    "evaluate_parameter_dict": ("mlaunch.launch_ros.params", "evaluate_dict"),
    "normalize_parameter_dict": ("mlaunch.launch_ros.params", "normalize_dict"),
    "normalize_parameters": ("mlaunch.launch_ros.params", "normalize_parameters"),
}

_SUBMODULES = {
    "actions": "mlaunch.launch_ros.actions",
    "substitutions": "mlaunch.launch_ros.substitutions",
    "parameter_descriptions": "mlaunch.launch_ros.parameter_descriptions",
    "descriptions": "mlaunch.launch_ros.descriptions",
    "events": "mlaunch.launch_ros.events",
    "event_handlers": "mlaunch.launch_ros.events",
    "utilities": "mlaunch.launch_ros",
}


def __getattr__(name: str) -> Any:
    if name in _NAMES:
        module_name, attribute = _NAMES[name]
        value = getattr(importlib.import_module(module_name), attribute)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(_SUBMODULES[name])
    raise AttributeError(f"module 'launch_ros' (mlaunch) has no attribute {name!r}")


def get_default_launch_description(*, prefix_output_with_name: bool = False) -> Any:
    """launch_ros's default description adds ROS logging setup; mlaunch needs none of it."""
    from mlaunch.launch.actions import LaunchDescription

    return LaunchDescription([])


def is_namespace_absolute(ns: str) -> bool:
    return ns.startswith("/")


def is_root_namespace(ns: str) -> bool:
    return ns == "/"


def evaluate_parameters(context: Any, parameters: Any) -> list[Any]:
    """launch_ros.utilities.evaluate_parameters: dicts evaluated, files as paths, Parameters."""
    from pathlib import Path

    from mlaunch.launch_ros.parameter_descriptions import ParameterFile
    from mlaunch.launch_ros.params import evaluate_dict as evaluate_parameter_dict

    out: list[Any] = []
    for entry in parameters:
        if isinstance(entry, dict):
            out.append(evaluate_parameter_dict(context, entry))
        elif isinstance(entry, ParameterFile):
            out.append(Path(entry.evaluate(context)))
        else:
            out.append(entry)
    return out


__all__ = [
    "evaluate_parameter_dict",
    "evaluate_parameters",
    "get_default_launch_description",
    "is_namespace_absolute",
    "is_root_namespace",
    "make_namespace_absolute",
    "normalize_parameter_dict",
    "normalize_parameters",
    "prefix_namespace",
]
