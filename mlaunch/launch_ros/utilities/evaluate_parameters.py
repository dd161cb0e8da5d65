"""``evaluate_parameters``: parameters from ``normalize_parameters`` performed with a context.

launch_ros's public evaluation: names performed, substitution values read with YAML and checked
(a scalar, or a non-empty list of one type), parameter files evaluated to paths, Parameter
entries kept. A value that is not a parameter is a TypeError, as in launch_ros. Values that
mlaunch's own Node normalization made (mlaunch.launch_ros.params) are evaluated too, with the
same rules and the same error type.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from mlaunch.launch.substitution import Substitution, perform_substitutions
from mlaunch.launch_ros import params
from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile, ParameterValue
from mlaunch.plan.errors import SubstitutionFailure

_STRING_HINT = (
    "; if the parameter is meant to be a string, wrap it in"
    " launch_ros.parameter_descriptions.ParameterValue(value, value_type=str)"
)
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
    if isinstance(value, ParameterValue):
        return value.evaluate(context)
    if isinstance(value, (params.Plain, params.Text, params.Items)):
        try:
            return params.evaluate_value(context, value, name)
        except SubstitutionFailure as error:
            raise TypeError(str(error)) from None
    if isinstance(value, tuple) and value:
        if isinstance(value[0], Substitution):
            return _from_yaml(perform_substitutions(context, value), name)
        if isinstance(value[0], tuple):
            items = [_yaml(perform_substitutions(context, item), name) for item in value]
            return _uniform(items, name)
        if all(isinstance(v, type(value[0])) for v in value) and type(value[0]) in SCALARS:
            return value
    elif isinstance(value, (bool, int, float, str, bytes)):
        return value
    raise TypeError(f"parameter {name!r}: {value!r:.120} is not a normalized parameter value")


def _from_yaml(text: str, name: str) -> Any:
    """Performed text read with YAML: a scalar or a uniform list (as a tuple)."""
    loaded = _yaml(text or "''", name)
    if type(loaded) in (*SCALARS, bytes):
        return loaded
    if isinstance(loaded, list):
        return _uniform(loaded, name)
    raise TypeError(
        f"parameter {name!r} is {text[:120]!r}, which YAML reads as {type(loaded).__name__}."
        " Allowed value types are bytes, bool, int, float, str and non-empty lists of one of"
        f" bool, int, float, str{_STRING_HINT}"
    )


def _yaml(text: str, name: str) -> Any:
    import yaml

    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as e:
        first = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise TypeError(
            f"Unable to parse the value of parameter {name!r} ({text[:120]!r}) as YAML: {first}"
            f"{_STRING_HINT}"
        ) from None


def _uniform(items: list[Any], name: str) -> tuple[Any, ...]:
    if items and type(items[0]) in SCALARS and all(isinstance(i, type(items[0])) for i in items):
        return tuple(items)
    raise TypeError(
        f"parameter {name!r} is {items!r:.160}: Expected a non-empty sequence with items of one"
        " type among bool, int, float, str"
    )


__all__ = ["evaluate_parameter_dict", "evaluate_parameters"]
