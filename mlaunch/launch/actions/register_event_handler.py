"""``launch.actions.register_event_handler``, where upstream defines it."""

from mlaunch.launch.actions import RegisterEventHandler

__all__ = ["RegisterEventHandler"]
