"""``launch.actions.unregister_event_handler``: stop listening with an event handler."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.actions.register_event_handler import REGISTERED
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import RemoveHandler

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class HandlerNotRegistered(LaunchFileError, ValueError):
    """Unregistering a handler that is not registered (a ValueError, as launch raises)."""


class UnregisterEventHandler(Action):
    """Unregister ``event_handler``; an error when it is not registered (as launch's)."""

    def __init__(self, event_handler: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.event_handler = event_handler

    def execute(self, context: LaunchContext) -> None:
        handler = self.event_handler
        here = handler in context._event_handlers
        run = context.run_state.get(REGISTERED, [])
        # A handler of the run counts even where this context is a copy made before it was
        # registered (a timer's body that takes its values where written).
        in_run = any(h is handler for h in run)
        if not here and not in_run:
            raise HandlerNotRegistered(
                f"UnregisterEventHandler: {type(handler).__name__} is not registered"
                " (never registered, or unregistered already)",
                where=self.origin,
            )
        if here:
            context._event_handlers.remove(handler)
        if in_run:
            run[:] = [h for h in run if h is not handler]
        context.planner.add(RemoveHandler(origin=self.origin, handler=handler))
