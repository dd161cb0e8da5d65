"""``launch.substitutions.equals_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import EqualsSubstitution

__all__ = ["EqualsSubstitution"]
