"""``launch_ros.event_handlers``: OnStateTransition (defined in mlaunch.launch_ros.events)."""

from mlaunch.launch_ros.events import OnStateTransition

__all__ = ["OnStateTransition"]
