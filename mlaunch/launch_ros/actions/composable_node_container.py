"""``launch_ros.actions.composable_node_container``, where upstream defines it."""

from mlaunch.launch_ros.actions import ComposableNodeContainer

__all__ = ["ComposableNodeContainer"]
