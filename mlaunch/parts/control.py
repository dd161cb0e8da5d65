"""Runtime control of a running launch: list, stop, start, restart, mute, unmute, logs.

The core of ``mlaunch ctl`` (through the control socket, mlaunch.parts.control_socket) and of the
``--status`` keys. The run (``mlaunch.app.parts.Run.control``) makes one Control on first
use; it asks the printer for what only the printer knows (mutes, log tails). Every method
runs on the supervisor's loop thread and never blocks: call it from a selector callback, a timer
(``Supervisor.schedule``) or a subscriber of the records. Another thread must hand its request
to the loop (the control socket is read by the loop's own selector, so it needs no hand-over).

What the user does reaches everything else through the record stream, as the launch's own
stops do:

- ``stop``: a ``Controlled`` record (the printer says the request), then the process's own stop
  ladder (SIGINT, SIGTERM after its ``sigterm_timeout``, SIGKILL after its
  ``sigkill_timeout``). Its exit is an ``Exited`` record with the real return code, so the
  launch file's OnProcessExit and ``on_exit`` handlers fire as they would for launch's
  ShutdownProcess (an ``on_exit=Shutdown()`` still ends the launch, with status 0); the
  printer says "process stopped by the user" (INFO), never "died"; the record's state becomes
  ``stopped`` and its outcome "stopped by the user" (status view, exit summary). Respawn does
  not start it again, a required process stopped this way does not end the run or fail it, and
  a pending respawn of a crashed process is cancelled. A launch whose only processes left are
  stopped by the user stays up (they can be started again); Ctrl-C ends it.
- ``start``: a process that is not running (stopped by the user, finished, failed, given up, or
  waiting for a respawn) starts again at once with the same label, argv and parameters.
- ``restart``: ``stop``, then ``start`` as soon as it has exited, with no respawn delay or
  backoff. Each start the user asks for adds one to the label's restart count but does not use
  up respawn's ``max_retries``, and starts the crash-loop backoff over.
- ``mute`` / ``unmute``: the label's output is kept off the screen (or shown again); its log
  file and launch.log still get every line.
- ``logs``: the last lines of the label's output, from its log file.

Requests that cannot be carried out raise ControlError (UnknownLabel for a label the run does
not have, with the valid labels and a did-you-mean); nothing changes then.

``done`` callbacks: ``stop`` calls it once the process has exited, ``restart`` once the new
instance has started (or failed to, or the launch began shutting down first), ``start`` at
once; each with the label's ProcessInfo at that moment.
"""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.engine.part import Part
from mlaunch.engine.process import Process
from mlaunch.engine.process_state import (
    RESTARTING,
    RUNNING,
    STOPPING,
    USER_STOPPED,
    ProcessState,
)
from mlaunch.plan.errors import EXIT_FAILURE, EXIT_USAGE, MlaunchError
from mlaunch.plan.records import Controlled, Exited, FailedToStart, NotStarted, Record, Started

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any, Protocol, TypeVar

    from mlaunch.engine.part import AttachedRun
    from mlaunch.plan.records import ProcessView

    class ControlledRun(AttachedRun, Protocol):
        """What runtime control uses of the run (the Supervisor is one): what it knows of each
        label and its processes, whether it is shutting down, a stop, a start again, a
        pending respawn cancelled."""

        @property
        def process_states(self) -> Mapping[str, ProcessState]: ...

        @property
        def processes(self) -> list[Process]: ...

        @property
        def shutting_down(self) -> bool: ...

        def stop(self, process: Process) -> None: ...

        def start_again(self, old: Process) -> object: ...

        def cancel_respawn(self, label: str, outcome: str) -> None: ...

    class Muting(Protocol):
        """What runtime control uses of the printer (mlaunch.engine.output's Printer is one):
        a label's output kept off the screen or shown again, and its last lines."""

        def is_muted(self, label: str) -> bool: ...

        def mute(self, label: str, muted: bool = True) -> None: ...

        def log_tail(self, label: str, count: int) -> list[bytes] | None: ...

    class ComponentLoads(Protocol):
        """What runtime control uses of the LoadNode driver (mlaunch.parts.components)."""

        def listed(self) -> list[dict[str, object]]: ...

        def unload(self, name: str, done: ComponentDone) -> None: ...

        def load(self, name: str, done: ComponentDone) -> None: ...

    class ManagedNode(Protocol):
        @property
        def fqn(self) -> str: ...

        @property
        def process(self) -> object: ...

    Node = TypeVar("Node", bound=ManagedNode)

    class LifecycleRequests(Protocol[Node]):
        """What runtime control uses of lifecycle driving (mlaunch.parts.lifecycle)."""

        def listed(self) -> list[dict[str, object]]: ...

        def find(self, name: str) -> Node | None: ...

        def request(self, managed: Node, label: str, done: ComponentDone) -> None: ...


# What a control request can ask, in the order ``mlaunch ctl --help`` lists them.
OPERATIONS = (
    "list",
    "stop",
    "start",
    "restart",
    "mute",
    "unmute",
    "logs",
    "unload",
    "load",
    "configure",
    "activate",
    "deactivate",
    "cleanup",
)
# Those that name a composable node rather than a process.
COMPONENT_OPERATIONS = ("unload", "load")
# The lifecycle transitions a user can ask of a managed node.
TRANSITIONS = ("configure", "activate", "deactivate", "cleanup")
DEFAULT_LINES = 20
# Labels an unknown-label error lists (a launch may have hundreds).
LISTED = 20


class ControlError(MlaunchError):
    """A control request that cannot be carried out now (not running, shutting down ...).

    ``exit_code`` is errors' table's: 1 for a request that is valid but cannot be done now, 2 for
    bad input (UnknownLabel).
    """

    exit_code = EXIT_FAILURE


class UnknownLabel(ControlError):
    """A label the run does not have; ``labels`` are the valid ones, ``close`` the nearest."""

    exit_code = EXIT_USAGE

    def __init__(self, label: str, labels: list[str]) -> None:
        import difflib  # only when a label is wrong

        self.label = label
        self.labels = labels
        self.close = difflib.get_close_matches(label, labels, n=3, cutoff=0.5)
        hint = f"; did you mean {' or '.join(repr(c) for c in self.close)}?" if self.close else ""
        shown = ", ".join(labels[:LISTED])
        if len(labels) > LISTED:
            shown += f" and {len(labels) - LISTED} more (mlaunch ctl list shows them)"
        super().__init__(f"no process {label!r} in this run{hint} (processes: {shown})")


class AmbiguousLabel(ControlError):
    """A name that several labels share (``talker`` for ``talker-1`` and ``talker-3``)."""

    exit_code = EXIT_USAGE

    def __init__(self, name: str, labels: list[str]) -> None:
        self.label = name
        self.labels = labels
        super().__init__(f"{name!r} names several processes: {', '.join(labels)}; give one label")


class UnknownNode(ControlError):
    """A composable node name the run does not have (or several of its nodes share)."""

    exit_code = EXIT_USAGE


class ProcessInfo:
    """One label as the user sees it: what ``list`` shows and ``done`` callbacks receive.

    ``uptime`` is seconds since its current instance started (None when not running);
    ``restart_in`` seconds until respawn starts it again (None unless one is pending);
    ``outcome`` how it last ended ("" while its first instance runs).
    """

    __slots__ = ("label", "muted", "outcome", "pid", "restart_in", "restarts", "state", "uptime")

    def __init__(
        self,
        label: str,
        state: str,
        pid: int,
        restarts: int,
        uptime: float | None,
        muted: bool,
        outcome: str,
        restart_in: float | None = None,
    ) -> None:
        self.label = label
        self.state = state
        self.pid = pid
        self.restarts = restarts
        self.uptime = uptime
        self.muted = muted
        self.outcome = outcome
        self.restart_in = restart_in

    def __repr__(self) -> str:
        return f"ProcessInfo({self.as_dict()!r})"

    def as_dict(self) -> dict[str, object]:
        """The fields as JSON-ready values (``mlaunch ctl --json``)."""
        return {name: getattr(self, name) for name in self.__slots__}


Done = Callable[[ProcessInfo], None]
ComponentDone = Callable[[dict[str, object]], None]


class Control(Part):
    """Stop, start, restart, mute and read one process of a running Supervisor (loop thread).

    ``by`` in every request says through what the user asked ("ctl", "keys"); the printer
    names it.
    """

    def __init__(
        self,
        supervisor: ControlledRun,
        printer: Muting,
        components: Callable[[], ComponentLoads | None] = lambda: None,
        lifecycle: Callable[[], LifecycleRequests[Any] | None] = lambda: None,
    ) -> None:
        self.supervisor = supervisor
        self.printer = printer
        # The LoadNode driver, once the run has one (unload and load a composable node).
        self.components = components
        # Lifecycle driving, once the run has it (a transition asked by the user).
        self.lifecycle = lifecycle
        # (process, what, callback): "exit" calls back when it exits, "restart" when its
        # label's next instance has started.
        self._waits: list[tuple[Process, str, Done]] = []
        supervisor.records.subscribe(self._on_record)

    # --- reading ---------------------------------------------------------------------------

    def labels(self) -> list[str]:
        """Every process label of the run so far, in the order they first started."""
        return list(self.supervisor.process_states)

    def resolve(self, name: str) -> str:
        """The label ``name`` means: a label, else the one label of that name (``talker`` for
        ``talker-1``: the name without launch's counter, or the node's name or full name).

        UnknownLabel (with the valid labels and the close ones) or AmbiguousLabel otherwise.
        """
        records = self.supervisor.process_states
        if name in records:
            return name
        named = [label for label, record in records.items() if name in _names(record)]
        if len(named) == 1:
            return named[0]
        if named:
            raise AmbiguousLabel(name, named)
        raise UnknownLabel(name, self.labels())

    def process_state(self, label: str) -> ProcessState:
        """What the run knows of the label ``label`` means (``resolve``)."""
        return self.supervisor.process_states[self.resolve(label)]

    def info(self, label: str) -> ProcessInfo:
        record = self.process_state(label)
        label = record.label
        running = record.state in (RUNNING, STOPPING)
        now = self.supervisor.clock()
        uptime = max(0.0, now - record.started_at) if running else None
        restart_at = record.restart_at if record.state == RESTARTING else None
        return ProcessInfo(
            label=label,
            state=record.state,
            pid=record.pid if running else 0,
            restarts=record.restarts,
            uptime=uptime,
            muted=self.is_muted(label),
            outcome=record.outcome,
            restart_in=None if restart_at is None else max(0.0, restart_at - now),
        )

    def processes(self) -> list[ProcessInfo]:
        """Every label's ProcessInfo, in the order they first started."""
        return [self.info(label) for label in self.labels()]

    def is_muted(self, label: str) -> bool:
        return self.printer.is_muted(label)

    def logs(self, label: str, lines: int = DEFAULT_LINES) -> list[str]:
        """The last ``lines`` lines of the label's output, oldest first, from its log file."""
        label = self.resolve(label)
        if lines < 0:
            raise ControlError(f"lines is {lines}; valid: 0 or more", what="logs")
        tail = self.printer.log_tail(label, lines)
        if tail is None:
            raise ControlError("this run writes no log files: no lines kept", what="logs")
        return [line.decode("utf-8", "replace") for line in tail]

    # --- acting ----------------------------------------------------------------------------

    def stop(self, label: str, *, by: str = "", done: Done | None = None) -> None:
        """Stop the label's process with its stop ladder; it stays down (respawn included)."""
        label, record, current = self._acting_on(label, "stop")
        supervisor = self.supervisor
        if current is not None and current.running:
            if current.user_stop:
                current.user_stop = "stop"  # a restart under way becomes a stop
            else:
                self._not_stopping(current, "stop")
                supervisor.records.emit(Controlled(label, "stop", by))
                current.user_stop = "stop"
                supervisor.stop(current)
            if done is not None:
                self._waits.append((current, "exit", done))
            return
        if record.state != RESTARTING:
            raise ControlError(f"{label} is not running ({record.outcome or record.state})")
        # Crashed and waiting for its respawn: the respawn is cancelled.
        supervisor.records.emit(Controlled(label, "stop", by))
        supervisor.cancel_respawn(label, USER_STOPPED)
        if done is not None:
            done(self.info(label))

    def start(self, label: str, *, by: str = "", done: Done | None = None) -> None:
        """Start a label that is not running again, at once (same label, argv, parameters)."""
        label, _, current = self._acting_on(label, "start")
        if current is not None and current.running:
            raise ControlError(f"{label} is already running [pid {current.pid}]")
        self._start(label, "start", by, current, done)

    def restart(self, label: str, *, by: str = "", done: Done | None = None) -> None:
        """Stop the label's process, then start it as soon as it has exited (no respawn delay).

        A label that is not running is started at once.
        """
        label, _, current = self._acting_on(label, "restart")
        supervisor = self.supervisor
        if current is None or not current.running:
            self._start(label, "restart", by, current, done)
            return
        if not current.user_stop:
            self._not_stopping(current, "restart")
            supervisor.records.emit(Controlled(label, "restart", by))
            supervisor.stop(current)
        current.user_stop = "restart"
        if done is not None:
            self._waits.append((current, "restart", done))

    def mute(self, label: str, *, by: str = "") -> ProcessInfo:
        """Keep the label's output off the screen (its log file still gets every line)."""
        label = self.resolve(label)
        if not self.is_muted(label):
            self.printer.mute(label)
            self.supervisor.records.emit(Controlled(label, "mute", by))
        return self.info(label)

    def unmute(self, label: str, *, by: str = "") -> ProcessInfo:
        """Show the label's output on the screen again."""
        label = self.resolve(label)
        if self.is_muted(label):
            self.printer.mute(label, False)
            self.supervisor.records.emit(Controlled(label, "unmute", by))
        return self.info(label)

    # --- composable nodes ------------------------------------------------------------------

    def composable_nodes(self) -> list[dict[str, object]]:
        """Every composable node of the run: container, name, plugin, state (any thread)."""
        driver = self.components()
        return [] if driver is None else driver.listed()

    def unload(self, name: str, *, by: str = "", done: ComponentDone) -> None:
        """Ask its container to unload the composable node ``name`` (its full name, or its
        name when only one has it); ``done(its state)`` once the container answered."""
        self._driver("unload").unload(name, done)
        self.supervisor.records.emit(Controlled(name, "unload", by))

    def load(self, name: str, *, by: str = "", done: ComponentDone) -> None:
        """Load the composable node ``name`` into its container again (after an unload, or a
        failed load); ``done(its state)`` once the container answered."""
        self._driver("load").load(name, done)
        self.supervisor.records.emit(Controlled(name, "load", by))

    def _driver(self, action: str) -> ComponentLoads:
        driver = self.components()
        if driver is None:
            raise ControlError(f"cannot {action}: this run has no composable nodes")
        if self.supervisor.shutting_down:
            raise ControlError(f"cannot {action}: the launch is shutting down")
        return driver

    # --- lifecycle nodes -------------------------------------------------------------------

    def lifecycle_nodes(self) -> list[dict[str, object]]:
        """Every lifecycle node of the run and its state (loop thread)."""
        manager = self.lifecycle()
        return [] if manager is None else manager.listed()

    def transition(self, name: str, label: str, *, by: str = "", done: ComponentDone) -> None:
        """Ask the lifecycle node ``name`` for the transition ``label`` (configure, activate,
        deactivate, cleanup); ``done(result)`` once it answered."""
        manager = self.lifecycle()
        if manager is None:
            raise ControlError(f"cannot {label}: this run has no lifecycle nodes")
        if self.supervisor.shutting_down:
            raise ControlError(f"cannot {label}: the launch is shutting down")
        managed = manager.find(name)
        if managed is None:
            names = ", ".join(str(n["name"]) for n in manager.listed())
            raise UnknownNode(
                f"no lifecycle node {name!r} in this run, or several (lifecycle nodes: {names})"
            )
        if managed.process is None:
            raise ControlError(f"cannot {label} {managed.fqn}: its process is not running")
        manager.request(managed, label, done)
        self.supervisor.records.emit(Controlled(managed.fqn, label, by))

    # --- the parts -------------------------------------------------------------------------

    def _acting_on(self, name: str, action: str) -> tuple[str, ProcessState, Process | None]:
        """The label, its record and latest instance, once the launch may still act on it."""
        record = self.process_state(name)
        label = record.label
        if self.supervisor.shutting_down:
            raise ControlError(f"cannot {action} {label}: the launch is shutting down")
        return label, record, self._current(label)

    def _current(self, label: str) -> Process | None:
        for process in reversed(self.supervisor.processes):
            if process.label == label:
                return process
        return None

    def _not_stopping(self, process: Process, action: str) -> None:
        if process.stopping:  # launch's own stop (ShutdownProcess): it is on its way out
            raise ControlError(f"cannot {action} {process.label}: it is already being stopped")

    def _start(
        self, label: str, action: str, by: str, current: Process | None, done: Done | None
    ) -> None:
        if current is None:  # every record comes from a start: a bug if this happens
            raise ControlError(f"cannot {action} {label}: no instance of it is known")
        self.supervisor.records.emit(Controlled(label, action, by))
        self.supervisor.start_again(current)
        if done is not None:
            done(self.info(label))

    def close(self) -> None:
        """Stop following the run (its waiting callbacks are dropped)."""
        self.supervisor.records.unsubscribe(self._on_record)
        self._waits.clear()

    def _on_record(self, record: Record) -> None:
        """Calls back those waiting for an exit, or for the start that follows a restart."""
        if not self._waits:
            return
        if isinstance(record, Exited):
            self._exited(record.process)
        elif isinstance(record, (Started, FailedToStart)):
            self._restarted(record.process.label)
        elif isinstance(record, NotStarted):
            self._restarted(record.spec.label)

    def _exited(self, process: ProcessView) -> None:
        for wait in list(self._waits):
            waited, what, done = wait
            if waited is not process:
                continue
            # A restart's new instance is started before this record is handed out (the exit
            # is held until the supervisor has acted on it); else it is still to come.
            if what == "exit" or self.supervisor.process_states[process.label].state != RESTARTING:
                self._waits.remove(wait)
                done(self.info(process.label))

    def _restarted(self, label: str) -> None:
        for wait in list(self._waits):
            waited, what, done = wait
            if what == "restart" and waited.label == label and not waited.running:
                self._waits.remove(wait)
                done(self.info(label))


def _names(record: ProcessState) -> set[str]:
    """What a label also goes by: without launch's ``-N`` counter, and its node's names."""
    base, _, number = record.label.rpartition("-")
    names = {base} if base and number.isdigit() else set()
    node = record.spec.node
    if node is not None and node.name:
        names.add(node.name)
        names.add(node.fully_qualified_name or node.name)
    return names
