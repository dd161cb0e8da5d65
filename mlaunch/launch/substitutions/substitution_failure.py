"""``launch.substitutions.substitution_failure``, where upstream defines it."""

from mlaunch.launch.substitutions import SubstitutionFailure

__all__ = ["SubstitutionFailure"]
