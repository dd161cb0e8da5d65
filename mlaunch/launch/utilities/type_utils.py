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

# The coercion of text is launch.frontend's (typing-free, so reading markup stays cheap).
from mlaunch.launch.frontend.coercion import (
    coerce_to_type,
    extract_type,
    get_typed_value,
    is_instance_of,
    is_instance_of_valid_type,
    is_typing_list,
)
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


def is_valid_scalar_type(data_type: Any) -> bool:
    """Whether ``data_type`` is one of the scalar types."""
    return data_type in ScalarTypesTuple


def coerce_list(value: list[str], data_type: Any = None, *, can_be_str: bool = False) -> Any:
    """Each text of ``value`` coerced to the scalar ``data_type``; the result must be uniform."""
    ensure_argument_type(value, list, "value", "coerce_list")
    result = [coerce_to_type(item, data_type, can_be_str=can_be_str) for item in value]
    if not is_instance_of_valid_type(result, can_be_str=can_be_str):
        raise ValueError(f"cannot convert value to {data_type}. Got value=`{value}`")
    return result


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


__all__ = [
    "AllowedTypesTuple",
    "ListTypesTuple",
    "ScalarTypesTuple",
    "coerce_list",
    "coerce_to_type",
    "extract_type",
    "get_typed_value",
    "is_instance_of",
    "is_instance_of_valid_type",
    "is_normalized_substitution",
    "is_substitution",
    "is_typing_list",
    "is_valid_scalar_type",
    "normalize_typed_substitution",
    "perform_typed_substitution",
]
