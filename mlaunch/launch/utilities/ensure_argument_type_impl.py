"""``ensure_argument_type``: the TypeError launch's constructors raise for a bad argument."""

from __future__ import annotations

import inspect
from collections.abc import Iterable
from typing import Any

_TEMPLATE = "{}xpected '{}' to be one of [{}], but got '{}' of type '{}'"


def _bad_call(name: str, expected: str, value: Any) -> TypeError:
    return TypeError(
        _TEMPLATE.format("'ensure_argument_type()' e", name, expected, value, type(value))
    )


def _matches(argument: Any, type_var: Any) -> bool:
    if isinstance(argument, type_var):
        return True
    return inspect.isclass(type_var) and issubclass(argument.__class__, type_var)


def ensure_argument_type(
    argument: Any,
    types: type | Iterable[type],
    argument_name: str,
    caller: str | None = None,
) -> None:
    """Raise TypeError unless ``argument`` is an instance of one of ``types``.

    The message names the caller (when given), the argument and the types, in launch's words.
    """
    if not isinstance(types, Iterable) and not isinstance(types, type):
        raise _bad_call("types", "type, collections.abc.Iterable of type", types)
    if not isinstance(argument_name, str):
        raise _bad_call("argument_name", "str", argument_name)
    if caller is not None and not isinstance(caller, str):
        raise _bad_call("caller", "str, None", caller)
    listed = list(types) if isinstance(types, Iterable) else [types]
    if any(_matches(argument, t) for t in listed):
        return
    raise TypeError(
        _TEMPLATE.format(
            "E" if caller is None else f"'{caller}' e",
            argument_name,
            ", ".join(str(t) for t in listed),
            argument,
            type(argument),
        )
    )
