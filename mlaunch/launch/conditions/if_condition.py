"""``launch.conditions.if_condition``: visit the action when the expression is true."""

from __future__ import annotations

from mlaunch.launch.condition import Condition
from mlaunch.launch.conditions.evaluate_condition_expression_impl import (
    evaluate_condition_expression,
)
from mlaunch.launch.substitution import describe, normalize

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class IfCondition(Condition):
    """True when the expression performs to true or 1 (false/0 otherwise; anything else fails)."""

    def __init__(self, predicate_expression: SomeSubstitutionsType) -> None:
        super().__init__()
        self.expression = normalize(predicate_expression)

    def evaluate(self, context: LaunchContext) -> bool:
        return evaluate_condition_expression(context, list(self.expression))

    def describe(self) -> str:
        return f"if {describe(self.expression)}"
