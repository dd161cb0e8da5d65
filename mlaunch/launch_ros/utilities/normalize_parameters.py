"""``normalize_parameters``: a Node's ``parameters=`` checked and normalized.

The normalized forms are mlaunch's own (mlaunch.launch_ros.params); a bad argument is a
TypeError, as in launch_ros, with mlaunch's words.
"""

from __future__ import annotations

from typing import Any

from mlaunch.launch_ros import params
from mlaunch.plan.errors import LaunchFileError


def normalize_parameters(parameters: Any) -> tuple[Any, ...]:
    """Dicts normalized, files and Parameter entries kept (TypeError for anything else)."""
    try:
        return params.normalize_parameters(parameters)
    except LaunchFileError as error:
        raise TypeError(str(error)) from None


def normalize_parameter_dict(parameters: Any) -> Any:
    """One dict of parameters normalized (nested dicts give dotted names)."""
    if not isinstance(parameters, dict):
        raise TypeError(f"expected a dict of parameters, got {type(parameters).__name__}")
    try:
        return params.normalize_dict(parameters)
    except LaunchFileError as error:
        raise TypeError(str(error)) from None
