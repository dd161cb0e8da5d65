"""``launch_ros.events.lifecycle.change_state``, where upstream defines it."""

from mlaunch.launch_ros.events.lifecycle import ChangeState

__all__ = ["ChangeState"]
