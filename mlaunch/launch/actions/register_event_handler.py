"""``launch.actions.register_event_handler``: listen with an event handler from here on.

Any handler registers: one of the kinds the engine dispatches itself (process start, exit,
output, shutdown, completion, a transition) or any other, whose ``matches(event)`` then decides
(``EventHandler(matcher=...)`` and handlers extensions write: the general path of the engine).
"""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.event_handler import register_step
from mlaunch.plan.errors import LaunchFileError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


# The handlers registered in a run (shared by every context of the run, as its state is):
# what UnregisterEventHandler may unregister, wherever its context was copied.
REGISTERED = "registered_event_handlers"


class RegisterEventHandler(Action):
    """Register ``event_handler`` with the context and the run's plan."""

    def __init__(self, event_handler: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.event_handler = event_handler

    def execute(self, context: LaunchContext) -> None:
        handler = self.event_handler
        step = register_step(context, handler, self.origin)
        if step is None:
            raise LaunchFileError(
                f"{type(handler).__name__} ({handler!r:.60}) is not an event handler: it has"
                " no matches(event) (launch.event_handler.EventHandler is the base class)",
                where=self.origin,
            )
        context._event_handlers.insert(0, handler)  # newest first, as upstream's context
        context.run_state.setdefault(REGISTERED, []).append(handler)
        context.planner.add(step)

    def describe_conditional_sub_entities(self) -> list[tuple[str, Iterable[Any]]]:
        """The handler's entities, run only when it handles an event (introspection)."""
        describe = getattr(self.event_handler, "describe", None)
        if describe is None:
            return []
        text, entities = describe()
        return [(text, list(entities))] if entities else []


__all__ = ["REGISTERED", "RegisterEventHandler"]
