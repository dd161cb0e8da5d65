"""``launch.actions.pop_environment``, where upstream defines it."""

from mlaunch.launch.actions.scoping import PopEnvironment

__all__ = ["PopEnvironment"]
