"""``launch.actions.push_environment``, where upstream defines it."""

from mlaunch.launch.actions.scoping import PushEnvironment

__all__ = ["PushEnvironment"]
