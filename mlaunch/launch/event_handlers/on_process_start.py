"""``launch.event_handlers.on_process_start``: what to visit when a process starts."""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler, check_target
from mlaunch.launch.launch_description_entity import check_entities

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


def _process_target(target: Any, handler: str) -> None:
    from mlaunch.launch.actions.execute_process import ExecuteProcess

    check_target(target, handler, ExecuteProcess, "an ExecuteProcess (or Node) action")


class OnProcessStart(EventHandler):
    kind = "process_start"

    def event_type(self) -> type:
        from mlaunch.launch.events.process.process_started import ProcessStarted

        return ProcessStarted

    def __init__(self, *, target_action: Any = None, on_start: Any, handle_once: bool = False):
        _process_target(target_action, "OnProcessStart")
        super().__init__(target_action=target_action, entities=on_start, handle_once=handle_once)
        check_entities(self.entities, "OnProcessStart")
