"""``launch_ros.events.lifecycle``: the lifecycle events (defined in mlaunch.launch_ros.events)."""

from mlaunch.launch_ros.events import ChangeState, StateTransition, matches_node_name

__all__ = ["ChangeState", "StateTransition", "matches_node_name"]
