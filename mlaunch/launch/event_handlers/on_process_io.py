"""``launch.event_handlers.on_process_io``: what to do with a process's output."""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler, returned_entities
from mlaunch.launch.event_handlers.on_process_start import _process_target

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


class OnProcessIO(EventHandler):
    """Callables receive the ProcessIO event (bytes in ``event.text``), as in ROS 2."""

    kind = "process_io"

    def event_type(self) -> type:
        from mlaunch.launch.events.process.process_io import ProcessIO

        return ProcessIO

    def __init__(
        self,
        *,
        target_action: Any = None,
        on_stdin: Callable[[Any], Any] | None = None,
        on_stdout: Callable[[Any], Any] | None = None,
        on_stderr: Callable[[Any], Any] | None = None,
        handle_once: bool = False,
    ) -> None:
        _process_target(target_action, "OnProcessIO")
        super().__init__(target_action=target_action, handle_once=handle_once)
        self.io_callbacks = {
            k: v for k, v in (("stdout", on_stdout), ("stderr", on_stderr)) if v is not None
        }
        self.on_stdin = on_stdin

    def handle(self, event: Any, context: Any) -> list[Any] | None:
        """The callback of the event's stream (stdin, stdout, stderr), given the event."""
        self._begin_handling(event, context)
        streams: dict[Any, Callable[[Any], Any] | None] = {
            0: self.on_stdin,
            1: self.io_callbacks.get("stdout"),
            2: self.io_callbacks.get("stderr"),
        }
        callback = streams.get(getattr(event, "fd", None))
        return None if callback is None else returned_entities(callback(event))
