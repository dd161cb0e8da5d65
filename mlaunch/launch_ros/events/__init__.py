"""launch_ros's lifecycle events and handler (``launch_ros.events(.lifecycle)``,
``launch_ros.event_handlers``), as data.

- ``ChangeState(lifecycle_node_matcher=..., transition_id=...)``: a launch file asks for a
  transition of the lifecycle nodes the matcher selects (``EmitEvent(event=ChangeState(...))``).
- ``StateTransition``: a lifecycle node made a transition (``transition``, ``start_state``,
  ``goal_state`` labels, as the ``TransitionEvent`` message gives them).
- ``OnStateTransition(entities=..., target_lifecycle_node=..., goal_state=...)``: resolve
  entities when a matching transition happens; a handler of kind ``state_transition``.

Turning these into service calls and transition events is the rclpy bridge's job; this module
imports no ROS package (the transition and state ids of lifecycle_msgs are restated here).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from mlaunch.launch.event_handlers import EventHandler
from mlaunch.launch.events import Event, matches_action
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


class StateTransition(Event):
    """A lifecycle node made a transition; labels as in its ``TransitionEvent`` message."""

    name = "launch_ros.events.lifecycle.StateTransition"

    def __init__(
        self,
        *,
        action: Any,
        msg: Any = None,
        transition: str | None = None,
        start_state: str | None = None,
        goal_state: str | None = None,
        stamp: Any = None,
    ) -> None:
        self.action = action
        self.msg = msg
        if msg is not None:
            transition = msg.transition.label
            start_state = msg.start_state.label
            goal_state = msg.goal_state.label
            stamp = getattr(msg, "timestamp", getattr(msg, "stamp", None))
        self.transition = transition or ""
        self.start_state = start_state or ""
        self.goal_state = goal_state or ""
        self.stamp = stamp

    def __repr__(self) -> str:
        return f"StateTransition({self.transition!r}: {self.start_state!r} -> {self.goal_state!r})"


class OnStateTransition(EventHandler):
    """Resolve ``entities`` when a lifecycle node makes a matching transition.

    Each of ``target_lifecycle_node``, ``transition``, ``start_state`` and ``goal_state`` that is
    given must match; a ``matcher(event)`` replaces them all (as in launch_ros).
    """

    kind = "state_transition"
    needs = LIFECYCLE  # the run attaches lifecycle driving (Plan.needs)

    def __init__(
        self,
        *,
        entities: Any,
        target_lifecycle_node: Any = None,
        transition: str | None = None,
        start_state: str | None = None,
        goal_state: str | None = None,
        matcher: Callable[[Any], bool] | None = None,
        handle_once: bool = False,
    ) -> None:
        from mlaunch.launch_ros.actions import LifecycleNode

        if target_lifecycle_node is not None and not isinstance(
            target_lifecycle_node, LifecycleNode
        ):
            raise TypeError(
                "OnStateTransition requires a LifecycleNode action as target_lifecycle_node,"
                f" got {type(target_lifecycle_node).__name__}"
            )
        super().__init__(
            target_action=target_lifecycle_node, entities=entities, handle_once=handle_once
        )
        self.target_lifecycle_node = target_lifecycle_node
        self.transition = transition
        self.start_state = start_state
        self.goal_state = goal_state
        self.event_matcher = matcher

    def matches(self, event: Any) -> bool:
        """Whether a StateTransition event is one this handler handles."""
        if self.event_matcher is not None:
            return bool(self.event_matcher(event))
        return (
            isinstance(event, StateTransition)
            and (self.target_lifecycle_node is None or event.action is self.target_lifecycle_node)
            and (self.transition is None or event.transition == self.transition)
            and (self.start_state is None or event.start_state == self.start_state)
            and (self.goal_state is None or event.goal_state == self.goal_state)
        )

    def describe_short(self) -> str:
        wanted = [
            f"{k}={v!r}"
            for k, v in (
                ("transition", self.transition),
                ("start_state", self.start_state),
                ("goal_state", self.goal_state),
            )
            if v is not None
        ]
        return f"OnStateTransition({', '.join(wanted)})"


def matches_node_name(node_name: str) -> LifecycleNodeMatcher:
    """A matcher for the lifecycle node with this full name (a Node action or a ProcessSpec);
    a name without the leading '/' is taken from the root, as launch_ros does."""
    if not node_name.startswith("/"):
        node_name = "/" + node_name

    def match(target: Any) -> bool:
        info = getattr(target, "node", None)  # a ProcessSpec carries NodeInfo
        if info is not None and hasattr(info, "fully_qualified_name"):
            return bool(info.fully_qualified_name == node_name)
        try:
            return bool(getattr(target, "node_name", None) == node_name)
        except RuntimeError:  # a Node not resolved yet has no name
            return False

    return match


__all__ = [
    "STATES",
    "TRANSITIONS",
    "ChangeState",
    "OnStateTransition",
    "StateTransition",
    "matches_action",
    "matches_node_name",
]
