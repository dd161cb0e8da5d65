"""``launch.event_handlers.on_process_start``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnProcessStart

__all__ = ["OnProcessStart"]
