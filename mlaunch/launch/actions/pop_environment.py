"""``launch.actions.pop_environment``, where upstream defines it."""

from mlaunch.launch.actions import PopEnvironment

__all__ = ["PopEnvironment"]
