"""``launch.substitutions.if_else_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import IfElseSubstitution

__all__ = ["IfElseSubstitution"]
