"""``LifecycleTransition``: walk lifecycle nodes through transitions, one after the other.

As launch_ros's: the first ChangeState of each node is emitted at once; each later one when the
node reaches the goal of the one before (an OnStateTransition handler, handled once). When the
last goal is reached, or a transition ends in errorprocessing, the node's remaining handlers are
unregistered.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from mlaunch.launch.action import Action
from mlaunch.launch.actions.emit_event import EmitEvent
from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
from mlaunch.launch.actions.unregister_event_handler import UnregisterEventHandler
from mlaunch.launch.substitution import normalize, perform_substitutions
from mlaunch.launch_ros.event_handlers.on_state_transition import OnStateTransition
from mlaunch.launch_ros.events.lifecycle.change_state import ChangeState
from mlaunch.launch_ros.events.lifecycle.state_transition import StateTransition
from mlaunch.launch_ros.events.matchers.matches_node_name import (
    matches_node_name as _matches_node_name,
)

# lifecycle_msgs Transition id -> the states a node passes through and reaches.
TRANSITION_TARGETS: dict[int, dict[str, str]] = {
    1: {"start_state": "configuring", "goal_state": "inactive"},
    2: {"start_state": "cleaningup", "goal_state": "unconfigured"},
    3: {"start_state": "activating", "goal_state": "active"},
    4: {"start_state": "deactivating", "goal_state": "inactive"},
    5: {"start_state": "shuttingdown", "goal_state": "finalized"},
    6: {"start_state": "shuttingdown", "goal_state": "finalized"},
    7: {"start_state": "shuttingdown", "goal_state": "finalized"},
}


def _absolute(node_name: str) -> str:
    return node_name if node_name.startswith("/") else "/" + node_name


def _node_name(event: Any) -> Any:
    try:
        return getattr(event.action, "node_name", None)
    except RuntimeError:  # a Node not resolved yet has no name
        return None


def match_node_name_start_goal(node_name: str, start_state: str, goal_state: str) -> Any:
    """A matcher of the StateTransition of ``node_name`` from ``start_state`` to ``goal_state``."""
    full = _absolute(node_name)
    return lambda event: (
        isinstance(event, StateTransition)
        and _node_name(event) == full
        and event.goal_state == goal_state
        and event.start_state == start_state
    )


def match_node_name_goal(node_name: str, goal_state: str) -> Any:
    """A matcher of any StateTransition of ``node_name`` that reaches ``goal_state``."""
    full = _absolute(node_name)
    return lambda event: (
        isinstance(event, StateTransition)
        and _node_name(event) == full
        and event.goal_state == goal_state
    )


class LifecycleTransition(Action):
    """Transitions ``transition_ids`` in turn for each node of ``lifecycle_node_names``."""

    transition_targets = TRANSITION_TARGETS

    def __init__(
        self,
        *,
        lifecycle_node_names: Sequence[Any],
        transition_ids: Sequence[Any],
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if len(transition_ids) == 0:
            raise ValueError("No transition_ids provided.")
        if len(lifecycle_node_names) == 0:
            raise ValueError("No lifecycle_node_names provided.")
        self.lifecycle_node_names = [normalize(name) for name in lifecycle_node_names]
        self.transition_ids = [
            normalize(str(tid) if isinstance(tid, int) else tid) for tid in transition_ids
        ]

    def _ids(self, context: Any) -> list[int]:
        ids = []
        for text in (perform_substitutions(context, t) for t in self.transition_ids):
            try:
                tid = int(text)
            except ValueError:
                raise ValueError(f"expected integer for lifecycle transition, got {text}") from None
            if tid not in TRANSITION_TARGETS:
                raise ValueError(
                    f"lifecycle transition {tid} has no goal state to wait for; valid:"
                    f" {sorted(TRANSITION_TARGETS)}"
                )
            ids.append(tid)
        return ids

    def execute(self, context: Any) -> list[Any]:
        names = [perform_substitutions(context, name) for name in self.lifecycle_node_names]
        ids = self._ids(context)
        registrations: list[Any] = []
        first_emits: list[Any] = []
        for name in names:
            emits = [
                EmitEvent(
                    event=ChangeState(
                        lifecycle_node_matcher=_matches_node_name(_absolute(name)),
                        transition_id=tid,
                    )
                )
                for tid in ids
            ]
            handlers = []
            for i, tid in enumerate(ids):
                states = TRANSITION_TARGETS[tid]
                matcher = match_node_name_start_goal(
                    name, states["start_state"], states["goal_state"]
                )
                then = [emits[i + 1]] if i + 1 < len(ids) else []
                handlers.append(OnStateTransition(entities=then, matcher=matcher, handle_once=True))
            on_error = OnStateTransition(
                entities=[UnregisterEventHandler(h) for h in handlers],
                matcher=match_node_name_goal(name, "errorprocessing"),
                handle_once=True,
            )
            # The last goal reached: the error handler is no longer wanted.
            handlers[-1].entities.append(UnregisterEventHandler(on_error))
            registrations.extend(RegisterEventHandler(h) for h in handlers)
            # Registered now, as launch_ros does (not among the returned actions).
            context.register_event_handler(on_error)
            first_emits.append(emits[0])
        return [*registrations, *first_emits]
