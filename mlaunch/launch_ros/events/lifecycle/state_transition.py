"""``launch_ros.events.lifecycle.state_transition``, where upstream defines it."""

from mlaunch.launch_ros.events.lifecycle import StateTransition

__all__ = ["StateTransition"]
