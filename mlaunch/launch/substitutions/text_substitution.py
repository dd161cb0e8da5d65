"""``launch.substitutions.text_substitution``, where upstream defines it."""

from mlaunch.launch.substitution import TextSubstitution

__all__ = ["TextSubstitution"]
