"""``launch.event_handlers.on_shutdown``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnShutdown

__all__ = ["OnShutdown"]
