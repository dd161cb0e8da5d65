"""``launch.substitutions.text_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import TextSubstitution

__all__ = ["TextSubstitution"]
