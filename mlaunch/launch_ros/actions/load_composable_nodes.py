"""``launch_ros.actions.load_composable_nodes``, where upstream defines it."""

from mlaunch.launch_ros.actions import LoadComposableNodes

__all__ = ["LoadComposableNodes"]
