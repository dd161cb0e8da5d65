"""``launch.substitutions.boolean_substitution``: Not, And, Or, Any and All, and the two readings
of a boolean text (``to_bool``, and the strict rule of a condition).
"""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform,
    perform_substitutions,
)
from mlaunch.plan.errors import InvalidConditionExpressionError, SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


_TRUE_WORDS = frozenset({"true", "yes", "on", "1", "y"})


_FALSE_WORDS = frozenset({"false", "no", "off", "0", "n"})


def to_bool(text: str, what: str) -> bool:
    """YAML-style boolean, as the boolean substitutions accept (true/yes/on/1 ...)."""
    lowered = text.strip().lower()
    if lowered in _TRUE_WORDS:
        return True
    if lowered in _FALSE_WORDS:
        return False
    raise SubstitutionFailure(f"{what} got {text!r}, which is not a boolean (true/false/1/0)")


def bool_value(context: LaunchContext, value: Any, what: str) -> bool:
    """A keyword given as a bool or as substitutions (performed and read as ``to_bool`` does)."""
    return value if isinstance(value, bool) else to_bool(perform(context, value), what)


def evaluate_condition_expression(text: str) -> bool:
    """The strict rule of IfCondition/UnlessCondition: only true, false, 1 and 0."""
    lowered = text.strip().lower()
    if lowered in ("true", "1"):
        return True
    if lowered in ("false", "0"):
        return False
    raise InvalidConditionExpressionError(
        f"condition expression is {text!r}; valid values are true, false, 1, 0"
    )


def bool_text(value: bool) -> str:
    return "true" if value else "false"


class NotSubstitution(Substitution):
    def __init__(self, value: SomeSubstitutionsType) -> None:
        self.value = normalize(value)

    def perform(self, context: LaunchContext) -> str:
        return bool_text(not to_bool(perform_substitutions(context, self.value), "not"))

    def describe(self) -> str:
        return f"Not({describe(self.value)})"


class _Many(Substitution):
    name = ""

    def __init__(self, *args: SomeSubstitutionsType) -> None:
        self.args = tuple(normalize(a) for a in args)

    def _values(self, context: LaunchContext) -> list[bool]:
        return [to_bool(perform_substitutions(context, a), self.name) for a in self.args]

    def describe(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(describe(a) for a in self.args) + ")"


class AndSubstitution(_Many):
    name = "and"

    def __init__(self, left: SomeSubstitutionsType, right: SomeSubstitutionsType) -> None:
        super().__init__(left, right)

    def perform(self, context: LaunchContext) -> str:
        return bool_text(all(self._values(context)))


class OrSubstitution(_Many):
    name = "or"

    def __init__(self, left: SomeSubstitutionsType, right: SomeSubstitutionsType) -> None:
        super().__init__(left, right)

    def perform(self, context: LaunchContext) -> str:
        return bool_text(any(self._values(context)))


class AnySubstitution(_Many):
    name = "any"

    def perform(self, context: LaunchContext) -> str:
        return bool_text(any(self._values(context)))


class AllSubstitution(_Many):
    name = "all"

    def perform(self, context: LaunchContext) -> str:
        return bool_text(all(self._values(context)))
