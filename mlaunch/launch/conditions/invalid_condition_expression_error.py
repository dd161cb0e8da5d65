"""``launch.conditions.invalid_condition_expression_error``, where upstream defines it."""

from mlaunch.launch.conditions import InvalidConditionExpressionError

__all__ = ["InvalidConditionExpressionError"]
