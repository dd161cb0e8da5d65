"""``launch.event_handlers.on_action_event_base``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnActionEventBase

__all__ = ["OnActionEventBase"]
