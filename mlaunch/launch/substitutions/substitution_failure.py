"""``launch.substitutions.substitution_failure``, where upstream defines it."""

from mlaunch.plan.errors import SubstitutionFailure

__all__ = ["SubstitutionFailure"]
