"""The engine's one record stream: typed records of what happens in a run, handled in order.

The supervisor emits a record for everything that happens (a process started, printed, exited;
a stop signal escalated; a respawn was scheduled; the launch began shutting down ...) and writes
no words of its own. Everything that reacts subscribes to the same RecordStream, in this order:
the supervisor's own reactions (starting the stop ladder), the printer (every log line), the
launch file's event handlers (mlaunch.engine.handlers), then what the pipeline attaches (status
view, lifecycle driving, smoke checks).

Dispatch follows launch's event queue: a record emitted while another is being dispatched, or
while a description is being visited (``held()``), waits in the queue; records are handled one
at a time, each by every subscriber, in the order they were emitted. So a handler registered
anywhere in a description sees the start of a process listed before it, and what a handler
does in reaction to one record is seen by everyone only after that record is done.

The records are plain classes with ``__slots__`` (dataclasses and typing cost start-up time,
and the first records are emitted before the first child runs).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any, Protocol

    from mlaunch.plan.steps import Handoff, ProcessSpec

    class ProcessView(Protocol):
        """What a record tells of one running (or ended) process: the engine's Process
        (mlaunch.engine.process) is one; this layer names only what subscribers read."""

        spec: ProcessSpec
        index: int
        restarts: int
        pid: int
        returncode: int | None
        started_at: float
        ended_at: float
        stopping: bool
        user_stop: str
        signals_sent: list[int]
        core_dumped: bool
        peak_rss: int
        cpu_time: float

        @property
        def label(self) -> str: ...

        @property
        def argv(self) -> tuple[str, ...]: ...

        @property
        def running(self) -> bool: ...


class Record:
    """A record on the stream. Subscribers tell them apart by class."""

    __slots__ = ()

    def __repr__(self) -> str:
        names: tuple[str, ...] = self.__slots__
        fields = ", ".join(f"{name}={getattr(self, name)!r}" for name in names)
        return f"{type(self).__name__}({fields})"


# --- processes ----------------------------------------------------------------------------------


class Started(Record):
    """A process is running (``process.restarts`` > 0: a respawn)."""

    __slots__ = ("process",)

    def __init__(self, process: ProcessView) -> None:
        self.process = process


class FailedToStart(Record):
    """The program could not be executed (``reason``: the OS's words). An Exited follows."""

    __slots__ = ("process", "reason")

    def __init__(self, process: ProcessView, reason: str) -> None:
        self.process = process
        self.reason = reason


class NotStarted(Record):
    """A start asked for while the launch was shutting down; nothing was spawned."""

    __slots__ = ("spec",)

    def __init__(self, spec: ProcessSpec) -> None:
        self.spec = spec


class StartsSkipped(Record):
    """A description being carried out asked for ``count`` starts while shutting down."""

    __slots__ = ("count",)

    def __init__(self, count: int) -> None:
        self.count = count


class Output(Record):
    """Complete lines (bytes ending in a newline) of a process's ``stream`` (stdout, stderr)."""

    __slots__ = ("data", "process", "stream")

    def __init__(self, process: ProcessView, stream: str, data: bytes) -> None:
        self.process = process
        self.stream = stream
        self.data = data


class Exited(Record):
    """A process ended (reaped, or failed to start) with ``code``: its status or -signal."""

    __slots__ = ("code", "process")

    def __init__(self, process: ProcessView, code: int) -> None:
        self.process = process
        self.code = code


class Escalated(Record):
    """A step of the stop ladder: ``signal`` sent, as ``previous`` went unheeded ``waited`` s
    (``previous`` 0: none was sent, the shutdown began ``waited`` s ago)."""

    __slots__ = ("previous", "process", "signal", "waited")

    def __init__(self, process: ProcessView, signal: int, previous: int, waited: float) -> None:
        self.process = process
        self.signal = signal
        self.previous = previous
        self.waited = waited


class RespawnScheduled(Record):
    """A process that exited with ``code`` starts again in ``delay`` s (restart ``attempt``)."""

    __slots__ = ("attempt", "code", "delay", "max_retries", "process")

    def __init__(
        self, process: ProcessView, code: int, attempt: int, max_retries: int, delay: float
    ) -> None:
        self.process = process
        self.code = code
        self.attempt = attempt
        self.max_retries = max_retries  # < 0: no limit
        self.delay = delay


class GaveUp(Record):
    """A respawning process used up its retries; it stays down."""

    __slots__ = ("code", "process", "restarts")

    def __init__(self, process: ProcessView, code: int, restarts: int) -> None:
        self.process = process
        self.code = code
        self.restarts = restarts


class StrayEnded(Record):
    """A process of the run outside every watched group (an escaped descendant) was signalled."""

    __slots__ = ("name", "pid", "signal")

    def __init__(self, name: str, pid: int, signal: int) -> None:
        self.name = name
        self.pid = pid
        self.signal = signal


class Controlled(Record):
    """The user asked for ``action`` on the process ``label`` (mlaunch.parts.control).

    ``action``: "stop", "start", "restart", "mute" or "unmute". Emitted before the action is
    carried out, so the printer says the request before what follows from it (the stop
    ladder's steps, the exit, the new start). ``by`` says through what: "ctl" (the control
    socket), "keys" (the --status view) or whatever an embedder passes.
    """

    __slots__ = ("action", "by", "label")

    def __init__(self, label: str, action: str, by: str = "") -> None:
        self.label = label
        self.action = action
        self.by = by


# --- the launch as a whole ------------------------------------------------------------------------


class Interrupted(Record):
    """The user (or the system) sent a stop signal: the launch stops (a second one kills)."""

    __slots__ = ("signal",)

    def __init__(self, signal: int) -> None:
        self.signal = signal


class ShutdownBegun(Record):
    """The first shutdown phase: the launch stops. OnShutdown handlers run now.

    ``due_to_signal``: the signal number when a signal caused it, else None. A handler that
    must act while processes still run (deactivating a lifecycle node) holds them back
    with ``Supervisor.hold_stop`` here; the ladder starts at the following StoppingAll.
    """

    __slots__ = ("due_to_signal", "reason")

    def __init__(self, reason: str, due_to_signal: int | None = None) -> None:
        self.reason = reason
        self.due_to_signal = due_to_signal


class ShutdownRepeated(Record):
    """Another Shutdown of the launch file while the launch already stops: its OnShutdown
    handlers see it, as launch hands them every Shutdown event; nothing else changes."""

    __slots__ = ("due_to_signal", "reason")

    def __init__(self, reason: str, due_to_signal: int | None = None) -> None:
        self.reason = reason
        self.due_to_signal = due_to_signal


class StoppingAll(Record):
    """The second shutdown phase: every process not held gets its stop ladder.

    With ``kill`` (a second Ctrl-C), every group was sent SIGKILL already.
    """

    __slots__ = ("kill",)

    def __init__(self, kill: bool = False) -> None:
        self.kill = kill  # a second Ctrl-C: SIGKILL to every group at once


class LaunchEvent(Record):
    """The launch file emitted ``event`` (EmitEvent); who acts on it sets ``taken``."""

    __slots__ = ("event", "taken")

    def __init__(self, event: object) -> None:
        self.event = event
        self.taken = False


class HandedOff(Record):
    """A plan step for a part of the run (``step``: a ``Handoff``, e.g. LoadComponents) was
    reached; the part that carries it out sets ``taken``."""

    __slots__ = ("step", "taken")

    def __init__(self, step: Handoff) -> None:
        self.step = step
        self.taken = False


class SimTimeWait(Record):
    """A ROSTimer's ``period`` counted on simulated time: the engine hands it to the ROS clock
    part (mlaunch.parts.ros_clock), which sets ``taken`` and calls ``expire`` from the loop
    once /clock has advanced ``period`` seconds past the time it had when the wait began (0
    before any message, as rclpy's clock under use_sim_time). ``cancel_on_shutdown``: dropped
    when the launch shuts down. Not taken, the engine counts the period on the wall clock.
    """

    __slots__ = ("cancel_on_shutdown", "expire", "origin", "period", "taken")

    def __init__(
        self, origin: str, period: float, expire: Callable[[], None], cancel_on_shutdown: bool
    ) -> None:
        self.origin = origin
        self.period = period
        self.expire = expire
        self.cancel_on_shutdown = cancel_on_shutdown
        self.taken = False


class Unclaimed(Record):
    """Follows a LaunchEvent or a HandedOff once every subscriber has seen it; said if nobody
    took it."""

    __slots__ = ("launch_event",)

    def __init__(self, launch_event: LaunchEvent | HandedOff) -> None:
        self.launch_event = launch_event


class LoadRefused(Record):
    """A container answered that it did not load a composable node: ``node`` its full name as
    requested (or its plugin when unnamed), ``reason`` the container's error message."""

    __slots__ = ("container", "node", "plugin", "reason")

    def __init__(self, container: str, node: str, plugin: str, reason: str) -> None:
        self.container = container
        self.node = node
        self.plugin = plugin
        self.reason = reason


class ComponentLoaded(Record):
    """A container loaded a composable node: ``step`` the LoadComponents it came from,
    ``request`` what was asked for, ``name`` the node's full name as the container answered."""

    __slots__ = ("name", "request", "step")

    def __init__(self, step: Handoff, request: Any, name: str) -> None:
        self.step = step
        self.request = request
        self.name = name


class Transition(Record):
    """A managed node changed state: ``event`` is launch_ros's StateTransition for ``spec``."""

    __slots__ = ("event", "spec")

    def __init__(self, spec: ProcessSpec, event: object) -> None:
        self.spec = spec
        self.event = event


class Completed(Record):
    """An action a handler waited for when it was visited finished executing (ExecutionComplete)."""

    __slots__ = ("action",)

    def __init__(self, action: object) -> None:
        self.action = action


class Said(Record):
    """A line whose words come from elsewhere: the plan's warnings, LogInfo, a handler's error."""

    __slots__ = ("level", "source", "text")

    def __init__(self, level: str, source: str, text: str) -> None:
        self.level = level
        self.source = source
        self.text = text


class Summary(Record):
    """Lines said as they are, not as one message (the exit summary's table)."""

    __slots__ = ("text",)

    def __init__(self, text: str) -> None:
        self.text = text


# --- the stream -----------------------------------------------------------------------------------

Subscriber = Callable[[Record], object]


class RecordStream:
    """Subscribers, and a queue that hands them each record in order, one record at a time."""

    def __init__(self) -> None:
        self.subscribers: list[Subscriber] = []
        self._queue: deque[Record] = deque()
        self._dispatching = False
        self._held = 0

    def subscribe(self, subscriber: Subscriber) -> None:
        """Called with every record from now on, after the subscribers already there."""
        self.subscribers.append(subscriber)

    def unsubscribe(self, subscriber: Subscriber) -> None:
        if subscriber in self.subscribers:
            self.subscribers.remove(subscriber)

    def emit(self, record: Record) -> None:
        """Queue ``record``; dispatch the queue now unless a dispatch or a visit is under way."""
        self._queue.append(record)
        if not self._dispatching and not self._held:
            self._drain()

    def say_now(self, record: Record) -> None:
        """Hand ``record`` to every subscriber at once, ahead of what is queued.

        Only for lines that are not events in launch (LogInfo is said while its description is
        visited, before the starts of that visit are handled).
        """
        for subscriber in list(self.subscribers):
            subscriber(record)

    def hold(self) -> None:
        """Queue without dispatching until the matching ``release`` (a description's visit)."""
        self._held += 1

    def release(self) -> None:
        self._held -= 1
        if not self._held and not self._dispatching:
            self._drain()

    @property
    def pending(self) -> int:
        """Records queued and not yet dispatched."""
        return len(self._queue)

    def _drain(self) -> None:
        self._dispatching = True
        queue = self._queue
        try:
            while queue:
                record = queue.popleft()
                for subscriber in list(self.subscribers):
                    subscriber(record)
        finally:
            self._dispatching = False
