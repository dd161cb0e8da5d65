"""``launch.substitutions.boolean_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import (
    AllSubstitution,
    AndSubstitution,
    AnySubstitution,
    NotSubstitution,
    OrSubstitution,
)

__all__ = [
    "AllSubstitution",
    "AndSubstitution",
    "AnySubstitution",
    "NotSubstitution",
    "OrSubstitution",
]
