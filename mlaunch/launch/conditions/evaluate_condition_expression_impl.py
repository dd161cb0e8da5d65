"""``launch.conditions.evaluate_condition_expression_impl``, where upstream defines it."""

from mlaunch.launch.conditions import (
    VALID_FALSE_EXPRESSIONS,
    VALID_TRUE_EXPRESSIONS,
    evaluate_condition_expression,
)

__all__ = ["VALID_FALSE_EXPRESSIONS", "VALID_TRUE_EXPRESSIONS", "evaluate_condition_expression"]
