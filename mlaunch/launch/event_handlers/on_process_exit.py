"""``launch.event_handlers.on_process_exit``: what to visit when a process exits."""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler
from mlaunch.launch.event_handlers.on_process_start import _process_target
from mlaunch.launch.launch_description_entity import check_entities

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class OnProcessExit(EventHandler):
    kind = "process_exit"

    def event_type(self) -> type:
        from mlaunch.launch.events.process.process_exited import ProcessExited

        return ProcessExited

    def __init__(self, *, target_action: Any = None, on_exit: Any, handle_once: bool = False):
        _process_target(target_action, "OnProcessExit")
        super().__init__(target_action=target_action, entities=on_exit, handle_once=handle_once)
        check_entities(self.entities, "OnProcessExit")
