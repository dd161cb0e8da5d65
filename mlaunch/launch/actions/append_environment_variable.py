"""``launch.actions.append_environment_variable``, where upstream defines it."""

from mlaunch.launch.actions import AppendEnvironmentVariable

__all__ = ["AppendEnvironmentVariable"]
