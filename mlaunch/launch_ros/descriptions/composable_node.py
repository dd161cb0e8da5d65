"""``launch_ros.descriptions.composable_node``, where upstream defines it."""

from mlaunch.launch_ros.descriptions import ComposableNode

__all__ = ["ComposableNode"]
