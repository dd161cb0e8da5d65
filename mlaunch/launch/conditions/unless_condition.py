"""``launch.conditions.unless_condition``, where upstream defines it."""

from mlaunch.launch.conditions import UnlessCondition

__all__ = ["UnlessCondition"]
