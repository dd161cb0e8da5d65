"""``launch_ros.event_handlers.on_state_transition``, where upstream defines it."""

from mlaunch.launch_ros.event_handlers import OnStateTransition

__all__ = ["OnStateTransition"]
