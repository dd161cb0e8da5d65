"""``launch.actions.unregister_event_handler``, where upstream defines it."""

from mlaunch.launch.actions import UnregisterEventHandler

__all__ = ["UnregisterEventHandler"]
