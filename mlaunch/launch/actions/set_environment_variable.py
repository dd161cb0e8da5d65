"""``launch.actions.set_environment_variable``, where upstream defines it."""

from mlaunch.launch.actions import SetEnvironmentVariable

__all__ = ["SetEnvironmentVariable"]
