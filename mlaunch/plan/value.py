"""Value: a dataclass's equality and repr for plain classes with ``__slots__``.

Importing dataclasses costs ~8 ms (it imports inspect, ast, dis and tokenize) and creating each
dataclass ~0.4 ms, all before the first child starts; the classes on the start-up path (the
Plan's steps, a node's names, normalized parameter values) are plain classes built on this.
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class Value:
    """Equality and repr over the names in ``_fields``, as a dataclass compares and shows itself.

    Equal when of the same class with equal fields; unhashable (defining ``__eq__`` removes the
    inherited ``__hash__``), as a mutable dataclass is.
    """

    __slots__ = ()
    _fields: tuple[str, ...] = ()

    def _values(self) -> tuple[Any, ...]:
        return tuple(getattr(self, name) for name in self._fields)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Value) or other.__class__ is not self.__class__:
            return NotImplemented
        return self._values() == other._values()

    def __repr__(self) -> str:
        fields = ", ".join(f"{name}={getattr(self, name)!r}" for name in self._fields)
        return f"{type(self).__qualname__}({fields})"
