"""``launch.actions.reset_environment``, where upstream defines it."""

from mlaunch.launch.actions.scoping import ResetEnvironment

__all__ = ["ResetEnvironment"]
