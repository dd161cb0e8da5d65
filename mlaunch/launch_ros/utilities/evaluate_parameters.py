"""``evaluate_parameters``: parameters from ``normalize_parameters`` performed with a context.

launch_ros's public evaluation: names performed, substitution values read with YAML and checked
(a scalar, or a non-empty list of one type), parameter files evaluated to paths, Parameter
entries kept. A value that is not a parameter is a TypeError, as in launch_ros (the reading and
the checks are mlaunch.launch_ros.params's, whose errors are TypeErrors too). Values that
mlaunch's own Node normalization made are evaluated too.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from mlaunch.launch.substitution import Substitution, perform_substitutions
from mlaunch.launch_ros import params
from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile, ParameterValue

SCALARS = (bool, int, float, str)


def evaluate_parameters(context: Any, parameters: Any) -> tuple[Any, ...]:
    """Dicts evaluated, parameter files as paths, Parameter entries as they are."""
    out: list[Any] = []
    for entry in parameters:
        if isinstance(entry, ParameterFile):
            out.append(entry.evaluate(context))
        elif isinstance(entry, Parameter):
            out.append(entry)
        elif isinstance(entry, Mapping):
            out.append(evaluate_parameter_dict(context, entry))
        else:
            raise TypeError(
                f"not a normalized parameters entry (a dict, a ParameterFile or a Parameter):"
                f" {type(entry).__name__}: {entry!r:.120}"
            )
    return tuple(out)


def evaluate_parameter_dict(context: Any, parameters: Any) -> dict[str, Any]:
    """``{name: value}`` of one normalized dict, performed and typed."""
    if not isinstance(parameters, Mapping):
        raise TypeError(f"expected a dict of normalized parameters, got {parameters!r:.120}")
    out: dict[str, Any] = {}
    for name, value in parameters.items():
        if not isinstance(name, tuple):
            raise TypeError(f"a normalized parameter name is a tuple of substitutions: {name!r}")
        text = perform_substitutions(context, name)
        out[text] = _evaluate_value(context, value, text)
    return out


def _evaluate_value(context: Any, value: Any, name: str) -> Any:
    if isinstance(value, (ParameterValue, params.Plain, params.Text, params.Items)):
        return params.evaluate_value(context, value, name)
    if isinstance(value, tuple) and value:
        if isinstance(value[0], Substitution):
            return params.typed_text(perform_substitutions(context, value), name)
        if isinstance(value[0], tuple):
            texts = [perform_substitutions(context, item) for item in value]
            return params.uniform([params.read_yaml(text, name) for text in texts], name)
        if all(isinstance(v, type(value[0])) for v in value) and type(value[0]) in SCALARS:
            return value
    elif isinstance(value, (*SCALARS, bytes)):
        return value
    raise TypeError(f"parameter {name!r}: {value!r:.120} is not a normalized parameter value")


__all__ = ["evaluate_parameter_dict", "evaluate_parameters"]
