"""``launch.event_handlers.on_process_exit``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnProcessExit

__all__ = ["OnProcessExit"]
