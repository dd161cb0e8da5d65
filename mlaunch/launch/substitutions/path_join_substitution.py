"""``launch.substitutions.path_join_substitution``, where upstream defines it."""

from mlaunch.launch.substitutions import PathJoinSubstitution

__all__ = ["PathJoinSubstitution"]
