"""``launch_ros.events.matchers``: the matcher of a lifecycle node by its name."""

from mlaunch.launch_ros.events import matches_node_name

__all__ = ["matches_node_name"]
