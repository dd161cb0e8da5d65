"""``evaluate_parameters``: normalized parameters performed with a context."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mlaunch.launch_ros.parameter_descriptions import ParameterFile
from mlaunch.launch_ros.params import evaluate_dict as evaluate_parameter_dict


def evaluate_parameters(context: Any, parameters: Any) -> tuple[Any, ...]:
    """Dicts evaluated, parameter files as paths, Parameter entries as they are."""
    out: list[Any] = []
    for entry in parameters:
        if isinstance(entry, dict):
            out.append(evaluate_parameter_dict(context, entry))
        elif isinstance(entry, ParameterFile):
            out.append(Path(entry.evaluate(context)))
        else:
            out.append(entry)
    return tuple(out)


__all__ = ["evaluate_parameter_dict", "evaluate_parameters"]
