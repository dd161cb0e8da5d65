"""Conditions: whether an action is visited, decided while resolving."""

from __future__ import annotations

from mlaunch.launch.substitutions import (
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import InvalidConditionExpressionError as _PlanError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitutions import SomeSubstitutionsType


VALID_TRUE_EXPRESSIONS = ["true", "1"]
VALID_FALSE_EXPRESSIONS = ["false", "0"]


class InvalidConditionExpressionError(_PlanError):
    """A condition expression that is not true, false, 1 or 0 (a ValueError, as launch's):
    what it performed to, what it was written as, and the valid values."""

    def __init__(
        self,
        expression: str,
        unexpanded_expression: Sequence[Any],
        valid_expressions: Sequence[str],
    ) -> None:
        written = " + ".join(str(sub) for sub in unexpanded_expression)
        super().__init__(
            f"invalid condition expression, expected one of [{', '.join(valid_expressions)}]"
            f" but got '{expression}', expanded from '{written}'"
        )


def evaluate_condition_expression(context: Any, expression: Sequence[Any]) -> bool:
    """True for 'true'/'1', False for 'false'/'0' (case and spaces ignored), else an error."""
    text = perform_substitutions(context, expression).strip().lower()
    if text in VALID_TRUE_EXPRESSIONS:
        return True
    if text in VALID_FALSE_EXPRESSIONS:
        return False
    raise InvalidConditionExpressionError(
        text, expression, VALID_TRUE_EXPRESSIONS + VALID_FALSE_EXPRESSIONS
    )


class Condition:
    """A predicate over the launch context."""

    def __init__(self, *, predicate: Callable[[Any], bool] | None = None) -> None:
        self._predicate = predicate

    def evaluate(self, context: LaunchContext) -> bool:
        """The predicate's answer; False without a predicate, as launch."""
        if self._predicate is None:
            return False
        return bool(self._predicate(context))

    def describe(self) -> str:
        return type(self).__name__


class IfCondition(Condition):
    """True when the expression performs to true or 1 (false/0 otherwise; anything else fails)."""

    def __init__(self, predicate_expression: SomeSubstitutionsType) -> None:
        super().__init__()
        self.expression = normalize(predicate_expression)

    def evaluate(self, context: LaunchContext) -> bool:
        return evaluate_condition_expression(context, list(self.expression))

    def describe(self) -> str:
        return f"if {describe(self.expression)}"


class UnlessCondition(IfCondition):
    def evaluate(self, context: LaunchContext) -> bool:
        return not super().evaluate(context)

    def describe(self) -> str:
        return f"unless {describe(self.expression)}"


class LaunchConfigurationEquals(Condition):
    """The configuration equals the expected text; ``expected_value=None`` means it is unset."""

    def __init__(self, launch_configuration_name: str, expected_value: Any) -> None:
        import warnings

        warnings.warn(
            "The 'LaunchConfigurationEquals' and 'LaunchConfigurationNotEquals' Conditions are"
            " deprecated. Use the 'EqualsSubstitution' and 'NotEqualsSubstitution' substitutions"
            " instead! E.g.:\n  IfCondition(\n  \tEqualsSubstitution("
            "LaunchConfiguration('some_launch_arg'), \"some_equality_check\")\n  )",
            UserWarning,
            stacklevel=2,
        )
        super().__init__()
        self.name = launch_configuration_name
        self.expected = None if expected_value is None else normalize(expected_value)

    def _matches(self, context: LaunchContext) -> bool:
        value = context.launch_configurations.get(self.name)
        if self.expected is None:
            return value is None
        return value is not None and value == perform_substitutions(context, self.expected)

    def evaluate(self, context: LaunchContext) -> bool:
        return self._matches(context)

    def describe(self) -> str:
        return f"{self.name} == {describe(self.expected) if self.expected else 'unset'}"


class LaunchConfigurationNotEquals(LaunchConfigurationEquals):
    def evaluate(self, context: LaunchContext) -> bool:
        return not self._matches(context)

    def describe(self) -> str:
        return f"{self.name} != {describe(self.expected) if self.expected else 'unset'}"


__all__ = [
    "Condition",
    "IfCondition",
    "InvalidConditionExpressionError",
    "LaunchConfigurationEquals",
    "LaunchConfigurationNotEquals",
    "UnlessCondition",
    "evaluate_condition_expression",
]
