"""``launch_ros.events.matchers.matches_node_name`` as upstream lays it out."""

from mlaunch.launch_ros.events import matches_node_name

__all__ = ["matches_node_name"]
