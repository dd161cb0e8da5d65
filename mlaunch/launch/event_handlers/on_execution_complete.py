"""``launch.event_handlers.on_execution_complete``: what to visit when an action finished."""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler, check_target
from mlaunch.launch.launch_description_entity import check_entities

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class OnExecutionComplete(EventHandler):
    """Fires when the target action completes: a process when it exits for good, a timer when
    it has fired; only for targets visited after the handler was registered (as in launch)."""

    kind = "execution_complete"

    def event_type(self) -> type:
        from mlaunch.launch.events.execution_complete import ExecutionComplete

        return ExecutionComplete

    def __init__(
        self, *, target_action: Any = None, on_completion: Any, handle_once: bool = False
    ) -> None:
        from mlaunch.launch.action import Action

        check_target(target_action, "OnExecutionComplete", Action, "an action")
        super().__init__(
            target_action=target_action, entities=on_completion, handle_once=handle_once
        )
        check_entities(self.entities, "OnExecutionComplete")
