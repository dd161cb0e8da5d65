"""``launch_ros.events.lifecycle.state_transition``: a lifecycle node made a transition
(``transition``, ``start_state``, ``goal_state`` labels, as the ``TransitionEvent`` message gives
them).
"""

from __future__ import annotations

from typing import Any

from mlaunch.launch.event import Event


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
