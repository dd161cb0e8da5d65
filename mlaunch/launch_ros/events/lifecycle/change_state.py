"""``launch_ros.events.lifecycle.change_state``: a launch file asks for a transition of the
lifecycle nodes a matcher selects (``EmitEvent(event=ChangeState(...))``).

Turning it into service calls is the rclpy bridge's job; this module imports no ROS package (the
transition and state ids of lifecycle_msgs are restated here).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from mlaunch.launch.event import Event
from mlaunch.plan.steps import LIFECYCLE

# lifecycle_msgs/msg/Transition and State ids, with their names.
TRANSITIONS: dict[int, str] = {
    0: "TRANSITION_CREATE",
    1: "TRANSITION_CONFIGURE",
    2: "TRANSITION_CLEANUP",
    3: "TRANSITION_ACTIVATE",
    4: "TRANSITION_DEACTIVATE",
    5: "TRANSITION_UNCONFIGURED_SHUTDOWN",
    6: "TRANSITION_INACTIVE_SHUTDOWN",
    7: "TRANSITION_ACTIVE_SHUTDOWN",
    8: "TRANSITION_DESTROY",
}


STATES: dict[int, str] = {
    0: "PRIMARY_STATE_UNKNOWN",
    1: "PRIMARY_STATE_UNCONFIGURED",
    2: "PRIMARY_STATE_INACTIVE",
    3: "PRIMARY_STATE_ACTIVE",
    4: "PRIMARY_STATE_FINALIZED",
    10: "TRANSITION_STATE_CONFIGURING",
    11: "TRANSITION_STATE_CLEANINGUP",
    12: "TRANSITION_STATE_SHUTTINGDOWN",
    13: "TRANSITION_STATE_ACTIVATING",
    14: "TRANSITION_STATE_DEACTIVATING",
    15: "TRANSITION_STATE_ERRORPROCESSING",
}


LifecycleNodeMatcher = Callable[[Any], bool]


class ChangeState(Event):
    """A request to move the matched lifecycle nodes through one transition."""

    name = "launch_ros.events.lifecycle.ChangeState"
    needs = LIFECYCLE  # the run attaches lifecycle driving (Plan.needs)
    valid_transitions = TRANSITIONS
    valid_states = STATES

    def __init__(self, *, lifecycle_node_matcher: LifecycleNodeMatcher, transition_id: int):
        if transition_id not in TRANSITIONS:
            valid = ", ".join(f"{k}: {v}" for k, v in TRANSITIONS.items())
            raise ValueError(
                f"given transition_id of {transition_id!r}, expected one of {{{valid}}}"
            )
        self.lifecycle_node_matcher = lifecycle_node_matcher
        self.transition_id = transition_id

    @property
    def transition_name(self) -> str:
        return TRANSITIONS[self.transition_id]

    def __repr__(self) -> str:
        return f"ChangeState({self.transition_name})"
