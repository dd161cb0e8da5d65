"""``launch.conditions.if_condition``, where upstream defines it."""

from mlaunch.launch.conditions import IfCondition

__all__ = ["IfCondition"]
