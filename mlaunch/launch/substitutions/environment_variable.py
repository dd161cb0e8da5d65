"""``launch.substitutions.environment_variable``, where upstream defines it."""

from mlaunch.launch.substitutions import EnvironmentVariable

__all__ = ["EnvironmentVariable"]
