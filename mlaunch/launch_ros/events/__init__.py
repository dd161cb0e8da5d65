"""``launch_ros.events``: launch_ros's events (the lifecycle ones in
``launch_ros.events.lifecycle``) and the matcher of a node by its name.

Each lives in its own module, named as upstream's; this package only gathers the names
(``mlaunch.launch.gathering``), the lifecycle handler ``OnStateTransition`` too, as it always
served it.
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.events.matchers import matches_action
    from mlaunch.launch_ros.event_handlers.on_state_transition import OnStateTransition
    from mlaunch.launch_ros.events.lifecycle.change_state import STATES, TRANSITIONS, ChangeState
    from mlaunch.launch_ros.events.lifecycle.state_transition import StateTransition
    from mlaunch.launch_ros.events.matchers.matches_node_name import matches_node_name

_gathered = Gathered(
    globals(),
    {
        "ChangeState": ".lifecycle.change_state",
        "OnStateTransition": "mlaunch.launch_ros.event_handlers.on_state_transition",
        "STATES": ".lifecycle.change_state",
        "StateTransition": ".lifecycle.state_transition",
        "TRANSITIONS": ".lifecycle.change_state",
        "matches_action": "mlaunch.launch.events.matchers",
        "matches_node_name": ".matchers.matches_node_name",
    },
    submodules=("lifecycle", "matchers"),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "STATES",
    "TRANSITIONS",
    "ChangeState",
    "OnStateTransition",
    "StateTransition",
    "matches_action",
    "matches_node_name",
]
