"""``launch.substitutions.local_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import LocalSubstitution

__all__ = ["LocalSubstitution"]
