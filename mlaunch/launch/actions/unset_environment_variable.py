"""``launch.actions.unset_environment_variable``, where upstream defines it."""

from mlaunch.launch.actions import UnsetEnvironmentVariable

__all__ = ["UnsetEnvironmentVariable"]
