"""``launch.actions.emit_event``: emit an event when the plan reaches this point."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.emission import emit_event_entities

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class EmitEvent(Action):
    def __init__(self, *, event: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.event = event

    def execute(self, context: LaunchContext) -> list[Any] | None:
        return emit_event_entities(context, self.event, self.origin)
