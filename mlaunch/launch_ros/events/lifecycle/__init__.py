"""``launch_ros.events.lifecycle``: the lifecycle events and the matcher of a lifecycle node.

Each lives in its own module, named as upstream's; this package only gathers the names.
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch_ros.events.lifecycle.change_state import ChangeState
    from mlaunch.launch_ros.events.lifecycle.state_transition import StateTransition
    from mlaunch.launch_ros.events.matchers.matches_node_name import matches_node_name

_gathered = Gathered(
    globals(),
    {
        "ChangeState": ".change_state",
        "StateTransition": ".state_transition",
        "matches_node_name": "mlaunch.launch_ros.events.matchers.matches_node_name",
    },
    submodules=("change_state", "lifecycle_node_matchers", "state_transition"),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = ["ChangeState", "StateTransition", "matches_node_name"]
