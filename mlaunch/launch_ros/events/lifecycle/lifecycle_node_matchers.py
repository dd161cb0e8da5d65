"""``launch_ros.events.lifecycle.lifecycle_node_matchers``, where upstream defines it."""

from mlaunch.launch_ros.events.matchers.matches_node_name import matches_node_name

__all__ = ["matches_node_name"]
