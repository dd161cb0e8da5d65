"""``launch.actions.opaque_function``, where upstream defines it."""

from mlaunch.launch.actions import OpaqueFunction

__all__ = ["OpaqueFunction"]
