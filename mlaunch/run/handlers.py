"""The launch file's event handlers (RegisterEventHandler, on_exit, OnProcessIO) while it runs.

The supervisor tells this module what happened to a process (started, output, exited) and that
the launch is shutting down; matching handlers resolve their bodies then (with the same resolve
code as the launch file) and the supervisor executes what they give.
"""

from __future__ import annotations

from mlaunch.launch import events as ev
from mlaunch.launch.event_handlers import returned_entities
from mlaunch.run.plan import AddHandler, Deferred
from mlaunch.run.process import Process

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.run.supervisor import Supervisor


class LaunchHandlers:
    """The registered handlers of one run, newest first (as ROS 2), and their dispatch."""

    def __init__(self, supervisor: Supervisor) -> None:
        self.supervisor = supervisor
        self.handlers: list[AddHandler] = []

    def add(self, step: AddHandler) -> None:
        self.handlers.insert(0, step)  # newest first, as ROS 2

    def remove(self, handler: object) -> None:
        self.handlers[:] = [h for h in self.handlers if h.handler is not handler]

    def dispatch(self, kind: str, process: Process | None, event: Any) -> None:
        """Fire every handler of ``kind`` whose matcher accepts ``process``'s spec."""
        for handler in list(self.handlers):
            if handler.kind != kind:
                continue
            if (
                process is not None
                and handler.matcher is not None
                and not handler.matcher(process.spec)
            ):
                continue
            if handler.once:
                self.handlers.remove(handler)
            if handler.body is not None:
                self.supervisor.fire(handler.body, event)

    def output(self, process: Process, stream: str, data: bytes) -> None:
        """Complete lines of a child to the OnProcessIO handlers that want its ``stream``."""
        event_type = ev.ProcessStdout if stream == "stdout" else ev.ProcessStderr
        for handler in list(self.handlers):
            if handler.kind != "process_io":
                continue
            if handler.matcher is not None and not handler.matcher(process.spec):
                continue
            callback = handler.io_callbacks.get(stream)
            if callback is None:
                continue
            if handler.once:
                self.handlers.remove(handler)
            event = event_type(
                action=process.spec.action,
                name=process.label,
                cmd=list(process.argv),
                pid=process.pid,
                text=data,
                fd=1 if stream == "stdout" else 2,
            )
            try:
                result = callback(event)
            except Exception as e:  # launch-file code: report it where it was written
                from mlaunch.origin import user_location

                where = user_location(e.__traceback__) or handler.origin
                self.supervisor.handler_failed(
                    f"{where}: OnProcessIO callback failed: {type(e).__name__}: {e}"
                )
                return
            entities = returned_entities(result)
            if entities and handler.body is not None:
                body = handler.body
                self.supervisor.fire(Deferred(entities, body.context, body.origin), event)
