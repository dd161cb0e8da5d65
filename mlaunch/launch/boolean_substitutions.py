"""The boolean substitutions of ROS 2 launch (Not, And, Or, Any, All, Equals, NotEquals,
IfElse) and the two readings of a boolean text: YAML-style for them, strict for conditions.
"""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    TextSubstitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import InvalidConditionExpressionError, SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import Subs


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


def _bool_text(value: bool) -> str:
    return "true" if value else "false"


class NotSubstitution(Substitution):
    def __init__(self, value: SomeSubstitutionsType) -> None:
        self.value = normalize(value)

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(not to_bool(perform_substitutions(context, self.value), "not"))

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
        return _bool_text(all(self._values(context)))


class OrSubstitution(_Many):
    name = "or"

    def __init__(self, left: SomeSubstitutionsType, right: SomeSubstitutionsType) -> None:
        super().__init__(left, right)

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(any(self._values(context)))


class AnySubstitution(_Many):
    name = "any"

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(any(self._values(context)))


class AllSubstitution(_Many):
    name = "all"

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(all(self._values(context)))


def _equal(left: str, right: str) -> bool:
    """Bool-aware, then float-aware, else textual comparison (EqualsSubstitution's rule)."""
    bools = {"true": True, "false": False}
    lb, rb = bools.get(left.strip().lower()), bools.get(right.strip().lower())
    if lb is not None or rb is not None:
        if lb is None and left.strip() in ("0", "1"):
            lb = left.strip() == "1"
        if rb is None and right.strip() in ("0", "1"):
            rb = right.strip() == "1"
        if lb is not None and rb is not None:
            return lb == rb
    import math

    try:
        return math.isclose(float(left), float(right))
    except ValueError:
        return left == right


def _equals_operand(value: Any) -> Subs:
    if value is None:
        return (TextSubstitution(text=""),)
    if isinstance(value, bool):
        return (TextSubstitution(text=_bool_text(value)),)
    return normalize(value)


class EqualsSubstitution(Substitution):
    def __init__(self, left: Any, right: Any) -> None:
        self.left = _equals_operand(left)
        self.right = _equals_operand(right)

    def perform(self, context: LaunchContext) -> str:
        left = perform_substitutions(context, self.left)
        right = perform_substitutions(context, self.right)
        return _bool_text(_equal(left, right))

    def describe(self) -> str:
        return f"Equals({describe(self.left)}, {describe(self.right)})"


class NotEqualsSubstitution(EqualsSubstitution):
    def perform(self, context: LaunchContext) -> str:
        return _bool_text(not to_bool(super().perform(context), "not-equals"))

    def describe(self) -> str:
        return f"NotEquals({describe(self.left)}, {describe(self.right)})"


class IfElseSubstitution(Substitution):
    """``if_value`` when the condition holds, else ``else_value``."""

    def __init__(
        self, condition: SomeSubstitutionsType, if_value: Any = "", else_value: Any = ""
    ) -> None:
        if if_value == else_value == "":
            # launch's error type and words (a RuntimeError, not a TypeError)
            raise RuntimeError("One of if_value and else_value must be specified")
        self.condition = normalize(condition)
        self.if_value = normalize(if_value)
        self.else_value = normalize(else_value)

    def perform(self, context: LaunchContext) -> str:
        # launch reads the condition as a typed bool (YAML's true/yes/on..., and 1/0)
        chosen = to_bool(perform_substitutions(context, self.condition), "IfElseSubstitution")
        return perform_substitutions(context, self.if_value if chosen else self.else_value)

    def describe(self) -> str:
        return (
            f"IfElse({describe(self.condition)}, {describe(self.if_value)},"
            f" {describe(self.else_value)})"
        )


__all__ = [
    "AllSubstitution",
    "AndSubstitution",
    "AnySubstitution",
    "EqualsSubstitution",
    "IfElseSubstitution",
    "NotEqualsSubstitution",
    "NotSubstitution",
    "OrSubstitution",
    "evaluate_condition_expression",
    "to_bool",
]
