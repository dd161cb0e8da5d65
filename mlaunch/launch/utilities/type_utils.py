"""Typed values that may be given as substitutions: launch's ``launch.utilities.type_utils``.

The allowed types are the scalars ``str``, ``int``, ``float``, ``bool`` and uniform lists of
one of them (``List[int]`` ...). A value written in a launch file may be such a value, a
substitution, or a list mixing scalars and substitutions; it is *normalized* when the action is
built (``normalize_typed_substitution``) and *performed* then coerced to the type when it runs
(``perform_typed_substitution``). Text is coerced with YAML rules, as launch does.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any, List, Union  # noqa: UP035 (List[...] is the type spelling launch reads)

from mlaunch.launch.substitution import Substitution
from mlaunch.launch.utilities.ensure_argument_type_impl import ensure_argument_type
from mlaunch.launch.utilities.normalize_to_list_of_substitutions_impl import (
    normalize_to_list_of_substitutions,
)
from mlaunch.launch.utilities.perform_substitutions_impl import perform_substitutions

ScalarTypesTuple = (int, float, bool, str)
ListTypesTuple = (List[int], List[float], List[bool], List[str])  # noqa: UP006
AllowedTypesTuple = ScalarTypesTuple + ListTypesTuple
ScalarTypesType = Any
ListTypesType = Any
AllowedTypesType = Any
ScalarValueType = Union[int, float, bool, str]  # noqa: UP007
ListValueType = Union[List[int], List[float], List[bool], List[str]]  # noqa: UP006, UP007
SequenceValueType = Union[Sequence[int], Sequence[float], Sequence[bool], Sequence[str]]  # noqa: UP007
AllowedValueType = Union[ScalarValueType, ListValueType]  # noqa: UP007
SomeScalarType = Union[ScalarValueType, Substitution, Sequence[Union[str, Substitution]]]  # noqa: UP007
SomeSequenceType = Sequence[Any]
SomeValueType = Union[SomeScalarType, SomeSequenceType]  # noqa: UP007
NormalizedScalarType = Union[ScalarValueType, List[Substitution]]  # noqa: UP006, UP007
NormalizedSequenceType = List[Any]  # noqa: UP006
NormalizedValueType = Union[NormalizedScalarType, NormalizedSequenceType]  # noqa: UP007
StrSomeScalarType = Union[ScalarValueType, str]  # noqa: UP007
StrSomeSequenceType = List[Any]  # noqa: UP006
StrSomeValueType = Union[StrSomeScalarType, StrSomeSequenceType]  # noqa: UP007

_TYPE_NAMES = "int, float, str, bool, List[int], List[float], List[str], List[bool]"


def is_typing_list(data_type: Any) -> bool:
    """Whether ``data_type`` is ``typing.List`` (or ``list``) or a subscription of it."""
    if data_type is List:  # noqa: UP006 (typing's bare List, which launch files may pass)
        return True
    origin = getattr(data_type, "__origin__", None)
    return hasattr(data_type, "__args__") and origin is list


def is_valid_scalar_type(data_type: Any) -> bool:
    """Whether ``data_type`` is one of the scalar types."""
    return data_type in ScalarTypesTuple


def extract_type(data_type: Any) -> tuple[Any, bool]:
    """(item type, is a list) of an allowed type; ValueError for any other."""
    scalar, is_list = data_type, False
    args = getattr(data_type, "__args__", None)
    if is_typing_list(data_type) and args:
        scalar, is_list = args[0], True
    if not is_valid_scalar_type(scalar):
        raise ValueError(f"Unrecognized data type: {data_type}")
    return scalar, is_list


def is_instance_of_valid_type(value: Any, *, can_be_str: bool = False) -> bool:
    """Whether ``value`` is a scalar or a uniform list of one scalar type (empty lists are).

    ``can_be_str``: a list may also mix strings in.
    """
    if not isinstance(value, list):
        return isinstance(value, ScalarTypesTuple)
    if not value:
        return True
    item_type = next((type(x) for x in value if type(x) is not str), str)
    if item_type not in ScalarTypesTuple:
        return False
    accepted = (item_type, str) if can_be_str else (item_type,)
    return all(isinstance(x, accepted) for x in value)


def is_instance_of(value: Any, data_type: Any = None, *, can_be_str: bool = False) -> bool:
    """Whether ``value`` is an instance of ``data_type`` (None: of any allowed type)."""
    if data_type is None:
        return is_instance_of_valid_type(value, can_be_str=can_be_str)
    scalar, is_list = extract_type(data_type)
    accepted = (str, scalar) if can_be_str else (scalar,)
    if not is_list:
        return isinstance(value, accepted)
    return isinstance(value, list) and all(isinstance(x, accepted) for x in value)


def _yaml_value(text: str, error: str, can_be_str: bool) -> Any:
    """``text`` read as YAML; an allowed type, or ValueError starting with ``error``."""
    if not text:
        return text
    import yaml

    try:
        value = yaml.safe_load(text)
    except Exception as exc:
        if can_be_str:
            return text
        raise ValueError(f"{error}: yaml.safe_load() failed\n{exc}") from None
    if not is_instance_of_valid_type(value, can_be_str=can_be_str):
        raise ValueError(f"{error}: output type is not allowed, got {type(value)}")
    return value


def _coerce_list(value: str, scalar: Any, can_be_str: bool) -> list[Any]:
    accepted = (str, scalar) if can_be_str else scalar
    error = f"Cannot convert value '{value}' to a list of '{accepted}'"
    items = _yaml_value(value, error, can_be_str)
    if not isinstance(items, list):
        raise ValueError(error)
    if not all(isinstance(x, accepted) for x in items):
        raise ValueError(f"{error}, got {items}")
    return items


def _coerce_number(value: str, scalar: type, can_be_str: bool) -> Any:
    try:
        return scalar(value)
    except ValueError:
        if can_be_str:
            return value
        raise


def coerce_to_type(value: str, data_type: Any = None, *, can_be_str: bool = False) -> Any:
    """Text as ``data_type`` (None: whatever YAML reads it as); ValueError when it is not one.

    A bool also accepts '1' and '0'. ``can_be_str``: text that cannot be coerced stays text.
    """
    ensure_argument_type(value, str, "value", "coerce_to_type")
    if data_type is None:
        return _yaml_value(value, f"Failed to convert '{value}' using yaml rules", can_be_str)
    scalar, is_list = extract_type(data_type)
    if is_list:
        return _coerce_list(value, scalar, can_be_str)
    if scalar is str:
        return value
    if scalar in (int, float):
        return _coerce_number(value, scalar, can_be_str)
    if scalar is not bool:
        raise ValueError(f"data_type is invalid. Expected one of: {_TYPE_NAMES}. Got {data_type}")
    text = {"1": "true", "0": "false"}.get(value, value)
    result = _yaml_value(text, f"Failed to convert '{text}' to '{scalar}'", can_be_str)
    if isinstance(result, (str, bool) if can_be_str else bool):
        return result
    raise ValueError(f"Cannot convert value '{text}' to '{scalar}'")


def coerce_list(value: list[str], data_type: Any = None, *, can_be_str: bool = False) -> Any:
    """Each text of ``value`` coerced to the scalar ``data_type``; the result must be uniform."""
    ensure_argument_type(value, list, "value", "coerce_list")
    result = [coerce_to_type(item, data_type, can_be_str=can_be_str) for item in value]
    if not is_instance_of_valid_type(result, can_be_str=can_be_str):
        raise ValueError(f"cannot convert value to {data_type}. Got value=`{value}`")
    return result


def get_typed_value(value: Any, data_type: Any, *, can_be_str: bool = False) -> Any:
    """A text or a list of texts coerced to ``data_type`` (a list needs a list type)."""
    if not isinstance(value, list):
        return coerce_to_type(value, data_type, can_be_str=can_be_str)
    if data_type is not None:
        data_type, is_list = extract_type(data_type)
        if not is_list:
            raise TypeError(
                f"Cannot convert input '{value}' of type '{type(value)}' to '{data_type}'"
            )
    return coerce_list(value, data_type, can_be_str=can_be_str)


def is_substitution(x: Any) -> bool:
    """A Substitution, or a non-empty iterable of text and substitutions with one at least."""
    if isinstance(x, Substitution):
        return True
    if not isinstance(x, Iterable) or isinstance(x, str):
        return False
    items = list(x)
    return (
        bool(items)
        and all(isinstance(i, (Substitution, str)) for i in items)
        and any(isinstance(i, Substitution) for i in items)
    )


def is_normalized_substitution(x: Any) -> bool:
    """A non-empty list of substitutions only."""
    return isinstance(x, list) and bool(x) and all(isinstance(i, Substitution) for i in x)


def _item_kinds(value: Iterable[Any]) -> set[type]:
    kinds: set[type] = set()
    for x in value:
        if isinstance(x, ScalarTypesTuple):
            kinds.add(type(x))
        elif is_substitution(x):
            kinds.add(Substitution)
        else:
            raise TypeError(
                "value is a list, and one of the items is not a scalar, a Substitution "
                f"or a list of substitutions. Got value='{value}'"
            )
    return kinds


# The uniform lists a normalized list may hold, with substitutions among the items: the item
# types allowed, the data type they make, and how a non-substitution item is kept.
_LIST_KINDS: tuple[tuple[set[type], type, Any], ...] = (
    ({str, Substitution}, str, lambda x: x),
    ({bool, Substitution}, bool, lambda x: x),
    ({int, Substitution}, int, lambda x: x),
    ({int, float, Substitution}, float, float),
)


def normalize_typed_substitution(value: Any, data_type: Any) -> Any:
    """``value`` (a scalar, a substitution, or a list of scalars and substitutions) checked
    against ``data_type`` and kept with its substitutions as lists (see the module docstring).

    A list of text and substitutions is read as one substitution; wrap the items in lists to
    make a list of them. TypeError when the value cannot become ``data_type``.
    """
    if isinstance(value, ScalarTypesTuple):
        if not is_instance_of(value, data_type):
            raise TypeError(f"value='{value}' is not an instance of {data_type}")
        return value
    if is_substitution(value):
        return normalize_to_list_of_substitutions(value)
    if not isinstance(value, Iterable):
        raise TypeError(
            "value should be either a scalar, a substitutions, or a mixed list of scalars and"
            f" substitutions. Got `value={value}` of type `{type(value)}`. "
        )
    kinds = _item_kinds(value)
    is_list = True
    if data_type is not None:
        data_type, is_list = extract_type(data_type)
    if not is_list:
        raise TypeError(
            "The provided value resolves to a list, though the required type is a scalar. "
            f"Got value='{value}', data_type='{data_type}'."
        )
    if kinds == {Substitution}:
        return [normalize_to_list_of_substitutions(x) for x in value]
    for allowed, item_type, keep in _LIST_KINDS:
        if kinds <= allowed:
            if data_type not in (None, item_type):
                raise TypeError(
                    f"Got a list of '{item_type}', expected a list of '{data_type}'."
                    f" value='{value}'"
                )
            return [
                keep(x) if not is_substitution(x) else normalize_to_list_of_substitutions(x)
                for x in value
            ]
    raise TypeError(f"Input value is not an acceptable 'SomeValueType'.Got value='{value}'")


def perform_typed_substitution(context: Any, value: Any, data_type: Any) -> Any:
    """A normalized value performed with ``context`` and coerced to ``data_type``."""
    if isinstance(value, ScalarTypesTuple):
        if data_type is not None and not is_instance_of(value, data_type):
            raise TypeError(f"value=`{value}` is a scalar and not an instance of `{data_type}`")
        return value
    if is_normalized_substitution(value):
        return coerce_to_type(perform_substitutions(context, value), data_type)
    if not isinstance(value, list):
        raise TypeError(
            f"Input value is not an acceptable 'NormalizedValueType'.Got value='{value}'"
        )
    scalar = None
    if data_type is not None:
        scalar, is_list = extract_type(data_type)
        if not is_list:
            raise ValueError(
                "The input value is a list, cannot convert it to a scalar. "
                f"Got value='{value}', expected type {scalar}."
            )
    result = [
        coerce_to_type(perform_substitutions(context, x), scalar)
        if is_normalized_substitution(x)
        else x
        for x in value
    ]
    if not is_instance_of(result, data_type):
        raise ValueError(
            "The output list does not match the expected type "
            f"Got value='{value}', expected type {scalar}."
            if scalar is not None
            else "The output list is not uniform"
        )
    return result
