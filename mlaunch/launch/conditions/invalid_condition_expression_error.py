"""``launch.conditions.invalid_condition_expression_error``: a condition expression that is not
true, false, 1 or 0.
"""

from __future__ import annotations

from mlaunch.plan.errors import InvalidConditionExpressionError as _PlanError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import Any


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
