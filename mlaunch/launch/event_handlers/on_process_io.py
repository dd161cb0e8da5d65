"""``launch.event_handlers.on_process_io``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnProcessIO

__all__ = ["OnProcessIO"]
