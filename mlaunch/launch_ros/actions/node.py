"""``launch_ros.actions.node``, where upstream defines it."""

from mlaunch.launch_ros.actions import Node

__all__ = ["Node"]
