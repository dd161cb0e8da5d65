"""``launch.substitutions.not_equals_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import NotEqualsSubstitution

__all__ = ["NotEqualsSubstitution"]
