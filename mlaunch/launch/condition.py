"""``launch.condition``, where upstream defines it."""

from mlaunch.launch.conditions import Condition

__all__ = ["Condition"]
