"""``launch.some_substitutions_type``, where upstream defines it."""

from mlaunch.launch.substitution import SomeSubstitutionsType, SomeSubstitutionsType_types_tuple

__all__ = ["SomeSubstitutionsType", "SomeSubstitutionsType_types_tuple"]
