"""How an event given to a context becomes a step of the plan (``EmitEvent``, ``Shutdown`` and
``LaunchContext.emit_event_sync`` share it).

A ``Shutdown`` event becomes the run's shutdown request, an ``IncludeLaunchDescription`` event
has its description visited there and then, and any other event is emitted when the plan
reaches that point. The context is read for its planner and ``noninteractive`` only, so the
context's own module can call this without importing it back.
"""

from __future__ import annotations

from mlaunch.plan.steps import EmitEvent, RequestShutdown

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any, Protocol

    from mlaunch.plan.planner import Planner

    class EmittingContext(Protocol):
        """What emitting reads of the context."""

        @property
        def planner(self) -> Planner: ...

        @property
        def noninteractive(self) -> bool: ...


def emit_event_entities(context: EmittingContext, event: Any, origin: str) -> list[Any] | None:
    """Plan the emission of ``event``; the entities to visit now for an include event."""
    from mlaunch.launch.events.include_launch_description import IncludeLaunchDescription
    from mlaunch.launch.events.shutdown import Shutdown

    step: RequestShutdown | EmitEvent | None = None
    if isinstance(event, Shutdown):
        sigint = bool(event.due_to_sigint)
        step = RequestShutdown(
            origin=origin,
            reason=event.reason,
            due_to_sigint=sigint,
            send_sigint=not sigint or context.noninteractive,
        )
    elif not isinstance(event, IncludeLaunchDescription):
        step = EmitEvent(origin=origin, event=event)
    context.planner.emit(event, step)
    # An included description is planned here and now, where the event was given.
    return [event.launch_description] if step is None else None
