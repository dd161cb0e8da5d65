"""``launch_ros.event_handlers.on_state_transition``: resolve entities when a matching
transition happens; a handler of kind ``state_transition``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from mlaunch.launch.event_handler import EventHandler
from mlaunch.launch_ros.events.lifecycle.state_transition import StateTransition
from mlaunch.plan.steps import LIFECYCLE


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
        from mlaunch.launch_ros.actions.lifecycle_node import LifecycleNode

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
