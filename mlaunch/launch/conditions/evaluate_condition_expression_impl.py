"""``launch.conditions.evaluate_condition_expression_impl``: the text of a condition read as true
or false, strictly.
"""

from __future__ import annotations

from mlaunch.launch.conditions.invalid_condition_expression_error import (
    InvalidConditionExpressionError,
)
from mlaunch.launch.substitution import perform_substitutions

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import Any


VALID_TRUE_EXPRESSIONS = ["true", "1"]


VALID_FALSE_EXPRESSIONS = ["false", "0"]


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
