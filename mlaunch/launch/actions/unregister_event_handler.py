"""``launch.actions.unregister_event_handler``, where upstream defines it."""

from mlaunch.launch.actions.register_event_handler import (
    HandlerNotRegistered,
    UnregisterEventHandler,
)

__all__ = ["HandlerNotRegistered", "UnregisterEventHandler"]
