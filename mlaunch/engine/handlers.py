"""The launch file's event handlers (RegisterEventHandler, on_exit, OnProcessIO) while it runs.

LaunchHandlers subscribes to the supervisor's RecordStream: each record of a process starting,
printing or exiting, of the launch shutting down, or of a managed node's transition becomes
the launch event launch_ros's handlers expect (mlaunch.launch.events), and every matching
handler fires; a handler of no kind dispatched here (``EventHandler(matcher=...)``) is offered
every event, and its ``matches(event)`` decides (``general``). The events a launch file
emits (EmitEvent: Shutdown, ShutdownProcess, SignalProcess) are acted on here too. A
handler's body is resolved when it fires, with the same resolve code as the launch file
(``Supervisor.fire``), and what it gives is carried out.
"""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.engine.process import Process
from mlaunch.launch import events as ev
from mlaunch.launch.event_handler import MATCHER_KIND, returned_entities
from mlaunch.launch.events.matchers import SEES_PROCESS
from mlaunch.plan.records import (
    Completed,
    Exited,
    LaunchEvent,
    Output,
    Record,
    ShutdownBegun,
    ShutdownRepeated,
    Started,
    Transition,
    Unclaimed,
)
from mlaunch.plan.steps import AddHandler, Deferred

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any, Protocol

    from mlaunch.plan.records import ProcessView, RecordStream

    class HandledRun(Protocol):
        """What the launch file's handlers use of the run (the Supervisor is one): its
        processes, the handlers' bodies fired, a failed handler said, a stop, the shutdown."""

        @property
        def processes(self) -> list[Process]: ...

        @property
        def shutting_down(self) -> bool: ...

        @property
        def records(self) -> RecordStream: ...

        def fire(self, body: Deferred, event: object, shutting_down: bool | None = None) -> None:
            """Resolve and carry out ``body`` for ``event``."""

        def handler_failed(self, message: str) -> None: ...

        def stop(self, process: Process) -> None: ...

        def begin_shutdown(self, reason: str, *, due_to_signal: int | None = None) -> None: ...


class LaunchHandlers:
    """The registered handlers of one run, newest first (as ROS 2), and their dispatch."""

    def __init__(self, supervisor: HandledRun) -> None:
        self.supervisor = supervisor
        self.handlers: list[AddHandler] = []

    def add(self, step: AddHandler) -> None:
        self.handlers.insert(0, step)  # newest first, as ROS 2

    def remove(self, handler: object) -> None:
        self.handlers[:] = [h for h in self.handlers if h.handler is not handler]

    def __call__(self, record: Record) -> None:
        """The subscription: the records launch has events for."""
        if isinstance(record, Output):
            if self.handlers:
                self.output(record.process, record.stream, record.data)
        elif isinstance(record, Started):
            self._started(record.process)
        elif isinstance(record, Exited):
            self._exited(record.process, record.code)
        elif isinstance(record, (ShutdownBegun, ShutdownRepeated)):
            sigint = record.due_to_signal == 2  # SIGINT, without importing signal for it
            self.dispatch("shutdown", None, ev.Shutdown(reason=record.reason, due_to_sigint=sigint))
        elif isinstance(record, Transition):
            self._transition(record)
        elif isinstance(record, LaunchEvent):
            self._launch_event(record)
        elif isinstance(record, Completed):
            self._completed(record.action)

    def wants_completion(self, action: object) -> bool:
        """Whether a handler registered now waits for ``action`` to complete.

        launch asks this as it visits an action: ExecutionComplete is emitted for it (when it
        completes) only if so, and then every matching handler of that moment handles it.
        """
        return any(_completes(h, action) or h.kind == MATCHER_KIND for h in self.handlers)

    def _completed(self, action: object) -> None:
        event = ev.ExecutionComplete(action=action)
        for handler in list(self.handlers):
            if not _completes(handler, action):
                continue
            if handler.once:
                self.handlers.remove(handler)
            if handler.body is not None:
                self.supervisor.fire(handler.body, event)
        self.general(event)

    def general(self, event: object) -> bool:
        """Fire the handlers of no kind the engine dispatches whose ``matches(event)`` accepts
        ``event`` (launch's general path: ``EventHandler(matcher=...)``); whether one did.

        A matcher is launch-file code: one that raises is said once, as the handler's failure,
        and the handler is dropped (the run shuts down)."""
        fired = False
        for handler in list(self.handlers):
            if handler.kind != MATCHER_KIND:
                continue
            try:
                matched = bool(handler.handler.matches(event))
            except Exception as e:
                from mlaunch.plan.origin import user_location

                if handler in self.handlers:
                    self.handlers.remove(handler)
                where = user_location(e.__traceback__) or handler.origin
                self.supervisor.handler_failed(
                    f"{where}: the matcher of an event handler failed: {type(e).__name__}: {e}"
                )
                continue
            if not matched:
                continue
            fired = True
            if handler.once and handler in self.handlers:
                self.handlers.remove(handler)
            if handler.body is not None:
                self.supervisor.fire(handler.body, event)
        return fired

    def _launch_event(self, record: LaunchEvent) -> None:
        """launch's own events: Shutdown, ShutdownProcess, SignalProcess.

        Others are for later subscribers (lifecycle takes ChangeState); the Unclaimed that
        follows is said by the printer if none did.
        """
        event, supervisor = record.event, self.supervisor
        if isinstance(event, ev.Shutdown):
            supervisor.begin_shutdown(event.reason)  # its handlers get it as the shutdown begins
        elif isinstance(event, ev.ExecutionComplete):  # an action without a process or timer
            self._completed(event.action)
        else:
            acted = self._act_on_processes(event)
            if not self.general(event) and not acted:
                supervisor.records.emit(Unclaimed(record))
                return
        record.taken = True

    def _act_on_processes(self, event: object) -> bool:
        """ShutdownProcess and SignalProcess carried out; whether ``event`` was one."""
        if isinstance(event, ev.ShutdownProcess):
            for p in self._running(event.process_matcher):
                self.supervisor.stop(p)
        elif isinstance(event, ev.SignalProcess):
            for p in self._running(event.process_matcher):
                p.signal_group(int(event.signal_number))
        else:
            return False
        return True

    def _running(self, matcher: Callable[[Any], bool] | None) -> list[Process]:
        processes = self.supervisor.processes
        return [p for p in processes if p.running and (matcher is None or _selects(matcher, p))]

    def _started(self, process: ProcessView) -> None:
        self.dispatch("process_start", process, ev.ProcessStarted(**_details(process)))

    def _exited(self, process: ProcessView, code: int) -> None:
        event = ev.ProcessExited(**_details(process), returncode=code)
        shutting_down = self.supervisor.shutting_down
        self.dispatch("process_exit", process, event)
        if process.spec.on_exit is not None:
            self.supervisor.fire(process.spec.on_exit, event, shutting_down)

    def _transition(self, record: Transition) -> None:
        """OnStateTransition handlers: their own matcher on the event, else on the node's spec."""
        for handler in list(self.handlers):
            if handler.kind != "state_transition":
                continue
            matches = getattr(handler.handler, "matches", None)
            if matches is not None:
                if not matches(record.event):
                    continue
            elif handler.matcher is not None and not handler.matcher(record.spec):
                continue
            if handler.once and handler in self.handlers:
                self.handlers.remove(handler)
            if handler.body is not None:
                self.supervisor.fire(handler.body, record.event)
        self.general(record.event)

    def dispatch(self, kind: str, process: ProcessView | None, event: Any) -> None:
        """Fire every handler of ``kind`` whose matcher accepts ``process``'s spec.

        Each sees the run as it was when the event came (``is_shutdown``), as in launch, where
        a Shutdown one handler returns is an event handled after them all.
        """
        shutting_down = self.supervisor.shutting_down
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
                self.supervisor.fire(handler.body, event, shutting_down)
        self.general(event)

    def output(self, process: ProcessView, stream: str, data: bytes) -> None:
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
            event = _io_event(event_type, process, stream, data)
            try:
                result = callback(event)
            except Exception as e:  # launch-file code: report it where it was written
                from mlaunch.plan.origin import user_location

                where = user_location(e.__traceback__) or handler.origin
                self.supervisor.handler_failed(
                    f"{where}: OnProcessIO callback failed: {type(e).__name__}: {e}"
                )
                return
            entities = returned_entities(result)
            if entities and handler.body is not None:
                body = handler.body
                deferred = Deferred(entities, body.context, body.origin, captured=body.captured)
                self.supervisor.fire(deferred, event)
        if any(h.kind == MATCHER_KIND for h in self.handlers):
            self.general(_io_event(event_type, process, stream, data))


def _selects(matcher: Callable[[Any], bool], process: Process) -> bool:
    """Whether a ShutdownProcess's or SignalProcess's matcher selects ``process``: launch's
    matchers are given the process's action, mlaunch's own (matches_pid ...) the process."""
    sees_process = getattr(matcher, SEES_PROCESS, False)
    return bool(matcher(process if sees_process else process.spec.action))


def _io_event(event_type: type, process: ProcessView, stream: str, data: bytes) -> Any:
    """launch's ProcessStdout/ProcessStderr of ``data`` (bytes) from ``process``."""
    return event_type(
        action=process.spec.action,
        name=process.label,
        cmd=list(process.argv),
        pid=process.pid,
        text=data,
        fd=1 if stream == "stdout" else 2,
    )


class _Target:
    """An action in the place of a ProcessSpec, for handler matchers (they read ``.action``)."""

    __slots__ = ("action",)

    def __init__(self, action: object) -> None:
        self.action = action


def _completes(handler: AddHandler, action: object) -> bool:
    if handler.kind != "execution_complete":
        return False
    return handler.matcher is None or bool(handler.matcher(_Target(action)))


def _details(process: ProcessView) -> dict[str, Any]:
    """What launch's process events carry about the process (ExecuteProcess.process_details)."""
    spec = process.spec
    return {
        "action": spec.action,
        "name": spec.label,
        "cmd": list(spec.argv),
        "cwd": spec.cwd,
        "env": spec.env,
        "pid": process.pid,
    }
