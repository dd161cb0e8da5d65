"""``launch.event_handler``, where upstream defines it."""

from mlaunch.launch.event_handlers import EventHandler

__all__ = ["EventHandler"]
