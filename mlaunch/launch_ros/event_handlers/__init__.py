"""``launch_ros.event_handlers``: the lifecycle handler ``OnStateTransition``.

This package only gathers the names (``mlaunch.launch.gathering``).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch_ros.event_handlers.on_state_transition import OnStateTransition

_gathered = Gathered(
    globals(),
    {
        "OnStateTransition": ".on_state_transition",
    },
    submodules=("on_state_transition",),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = ["OnStateTransition"]
