"""``normalize_parameters``: a Node's ``parameters=`` in launch_ros's normalized shapes.

This is the public function of launch_ros, for launch-file code that normalizes and evaluates
parameters itself (``evaluate_parameters`` takes what it returns). A dict becomes
``{name: value}`` where the name is a tuple of substitutions and the value is one of:

- a ``ParameterValue``, a bool, int, float or bytes, kept;
- a tuple of substitutions (a substitution, or text dumped as YAML so that it reads back as
  that text): performed to one string and read with YAML when evaluated;
- a tuple of bools, ints or floats (ints among floats become floats);
- a tuple of substitution tuples, one per item of a list that mixes kinds (plain items dumped
  as YAML): each performed and read with YAML, and the results must be of one type.

Nested dicts are flattened (``{'a': {'b': 1}}`` -> ``a.b``). Paths and substitutions become a
``ParameterFile``. A bad argument is a TypeError.

A Node does not use these shapes: mlaunch.launch_ros.params normalizes its parameters with the
same rules into values that remember their parameter's name, so that a bad value in a run is an
error naming the parameter, its value and where it was written.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from mlaunch.launch.substitution import Substitution, TextSubstitution, describe, normalize
from mlaunch.launch_ros import params
from mlaunch.launch_ros.parameter_descriptions import ParameterValue
from mlaunch.launch_ros.params import parameter_name

Subs = tuple[Substitution, ...]


def normalize_parameters(parameters: Any) -> tuple[Any, ...]:
    """Dicts normalized, Parameter and ParameterFile kept, paths and substitutions made a
    ParameterFile; anything else is a TypeError."""
    return params.normalize_parameters(parameters, normalize_parameter_dict)


def normalize_parameter_dict(parameters: Any, *, _prefix: Subs | None = None) -> dict[Subs, Any]:
    """One dict of parameters normalized (see the module docstring); nested dicts flattened."""
    if not isinstance(parameters, Mapping):
        raise TypeError(
            f"expected a dict of parameters, got {type(parameters).__name__}: {parameters!r:.120}"
        )
    out: dict[Subs, Any] = {}
    for raw_name, value in parameters.items():
        name = parameter_name(raw_name)
        if _prefix:
            name = (*_prefix, TextSubstitution(text="."), *name)
        if isinstance(value, Mapping):
            out.update(normalize_parameter_dict(value, _prefix=name))
        else:
            out[name] = _normalize_value(value, name)
    return out


def _yaml_text(value: Any) -> Subs:
    """A plain value as the YAML text that reads back as that value."""
    import yaml

    return (TextSubstitution(text=yaml.dump(value)),)


def _normalize_value(value: Any, name: Subs) -> Any:
    if isinstance(value, ParameterValue):
        return value
    if isinstance(value, str):
        return _yaml_text(value)
    if isinstance(value, Substitution):
        return (value,)
    if isinstance(value, (bool, int, float, bytes)):
        return value
    if isinstance(value, Sequence):
        return _normalize_list(value, name)
    raise TypeError(
        f"parameter {_shown(name)}: a value must be text, a number, a bool, bytes, a"
        f" substitution, a list or a dict, got {type(value).__name__}: {value!r:.120}"
    )


def _normalize_list(value: Sequence[Any], name: Subs) -> tuple[Any, ...]:
    kinds = {_item_kind(item, name) for item in value}
    if kinds == {int}:
        return tuple(int(v) for v in value)
    if kinds in ({float}, {int, float}):
        return tuple(float(v) for v in value)
    if Substitution in kinds and kinds <= {str, Substitution}:
        return normalize(value)  # text and substitutions make one string
    if kinds == {bool}:
        return tuple(bool(v) for v in value)
    # Mixed kinds: each item its own text, read with YAML (and checked) when evaluated.
    return tuple(
        _yaml_text(v) if isinstance(v, (bool, int, float, str)) else normalize(v) for v in value
    )


def _item_kind(item: Any, name: Subs) -> type:
    if isinstance(item, Substitution):
        return Substitution
    if isinstance(item, (str, bool, int, float)):
        return type(item)
    if isinstance(item, Sequence) and all(isinstance(i, (str, Substitution)) for i in item):
        return tuple
    raise TypeError(
        f"parameter {_shown(name)}: list item {item!r:.80} is not text, a number, a bool, a"
        " substitution or a list of text and substitutions (nested lists are not parameters)"
    )


def _shown(name: Subs) -> str:
    return describe(name)


__all__ = ["normalize_parameter_dict", "normalize_parameters"]
