"""``launch.event_handlers.on_shutdown``: what to visit when the launch shuts down."""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class OnShutdown(EventHandler):
    kind = "shutdown"

    def event_type(self) -> type:
        from mlaunch.launch.events.shutdown import Shutdown

        return Shutdown

    def __init__(self, *, on_shutdown: Any, handle_once: bool = False) -> None:
        super().__init__(entities=on_shutdown, handle_once=handle_once)
        self.on_shutdown = on_shutdown

    def handle(self, event: Any, context: Any) -> Any:
        """What ``on_shutdown`` gives: its entities as given, or the callable's result."""
        self._begin_handling(event, context)
        if self.callback is not None:
            return self.callback(event, context)
        return self.on_shutdown
