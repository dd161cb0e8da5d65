"""``launch_ros.actions.lifecycle_node``, where upstream defines it."""

from mlaunch.launch_ros.actions import LifecycleNode

__all__ = ["LifecycleNode"]
