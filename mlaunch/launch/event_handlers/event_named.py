"""``launch.event_handlers.event_named``, where upstream defines it."""

from mlaunch.launch.event_handlers import event_named

__all__ = ["event_named"]
