"""``launch_ros.events.matchers``: the matcher of a lifecycle node by its name (the function,
as upstream's package serves it in place of its module of the same name)."""

from mlaunch.launch_ros.events.matchers.matches_node_name import matches_node_name

__all__ = ["matches_node_name"]
