"""run(plan) -> exit code: start processes, stream their output, fire triggers, stop everything.

One thread, one ``selectors`` loop. Signal handlers only record the signal (and wake the loop
through ``signal.set_wakeup_fd``); the loop acts on them. Every child runs in its own session, so
the stop ladder (SIGINT, then SIGTERM after sigterm_timeout, then SIGKILL after sigkill_timeout,
each with SIGCONT so a stopped process wakes up to die) reaches its whole process group.

Nothing is left behind:
- mlaunch becomes the children's subreaper, so a grandchild that escapes into a session of its
  own is re-parented to mlaunch, not to init;
- every child's environment carries ``MLAUNCH_RUN_ID=<run id>`` (inherited by grandchildren), so
  at shutdown any process of the run is found in /proc even if it escaped before the subreaper
  was set, and is ended (SIGTERM, SIGKILL after STRAY_GRACE);
- a guard process (mlaunch.run.guard, a constructor seam) ends the run if mlaunch itself is killed;
- if the loop itself fails, every group is killed before the error propagates.

At shutdown the stray sweep walks mlaunch's process tree (/proc/<pid>/task/*/children, a few
reads); the full /proc scan for the marker (every process's environment) is only made when the
walk cannot be trusted to see everything: without the subreaper, or when a child had already
exited before the subreaper was set (its orphans went to init).

Output flow: while the terminal has a backlog, its fd is in the selector for writability, so the
backlog is written as fast as the reader takes it; while the backlog is above its high-water
mark (``Printer.holding()``), a child's pipe that becomes readable is taken out of the selector
until the terminal catches up, so the children block on their own pipes instead of losing lines.
A reader that has stalled (nothing taken for ~1 s) holds nobody: the Screen drops, and says so.

The per-label ProcessRecord (state, restarts, run time, peak memory) is what the status view and
the exit summary read; peak memory and CPU time come from wait4's rusage, so nothing is sampled.
"""

from __future__ import annotations

import heapq
import itertools
import os
import selectors
import signal
import time
from collections.abc import Callable

from mlaunch.errors import MlaunchError
from mlaunch.launch import events as ev
from mlaunch.run import guard as guards
from mlaunch.run.output import Printer
from mlaunch.run.plan import (
    AddHandler,
    Deferred,
    EmitEvent,
    Log,
    Plan,
    ProcessSpec,
    RemoveHandler,
    RequestShutdown,
    RespawnPolicy,
    Spawn,
    StartTimer,
    Step,
)
from mlaunch.run.process import (
    Process,
    core_dump_hint,
    core_limit,
    describe_status,
    read_core_pattern,
    signal_name,
)
from mlaunch.run.resolve import LabelCounter, ResolveOptions, resolve_deferred

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

EXIT_OK = 0
EXIT_REQUIRED_FAILED = 1
EXIT_LAUNCH_ERROR = 2
# A crash loop's backoff starts over once a process has stayed up this long.
STABLE_UPTIME = 10.0
# With respawn_backoff > 1 but no respawn_delay, the backoff grows from this (0 * 2**n is 0).
BACKOFF_BASE = 0.1
# How long an escaped descendant gets between SIGTERM and SIGKILL at shutdown.
STRAY_GRACE = 2.0
# How often the loop looks at lingering groups, strays and a blocked terminal while it waits.
POLL = 0.05
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
PR_SET_CHILD_SUBREAPER = 36

# ProcessRecord.state values.
RUNNING = "running"
STOPPING = "stopping"
RESTARTING = "restarting"
FINISHED = "finished"
FAILED = "failed"
GAVE_UP = "gave up"


class _Timer:
    """A pending callback in the loop's heap (a plain class: dataclass creation costs start-up)."""

    __slots__ = ("callback", "cancel_on_shutdown", "cancelled", "keeps_alive", "seq", "when")

    def __init__(
        self,
        when: float,
        seq: int,
        callback: Callable[[], None],
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> None:
        self.when = when
        self.seq = seq
        self.callback = callback
        self.keeps_alive = keeps_alive
        self.cancel_on_shutdown = cancel_on_shutdown
        self.cancelled = False

    def __lt__(self, other: _Timer) -> bool:
        return (self.when, self.seq) < (other.when, other.seq)


class ProcessRecord:
    """One process label over the whole run (all its respawns): for the status view and summary.

    A plain class (dataclass creation is start-up cost); every field is a keyword argument.
    """

    __slots__ = (
        "cpu_time",
        "failed",
        "label",
        "outcome",
        "peak_rss",
        "pid",
        "restart_at",
        "restarts",
        "returncode",
        "run_time",
        "signals",
        "spec",
        "started_at",
        "state",
        "streak",
    )

    def __init__(
        self,
        label: str,
        spec: ProcessSpec,
        state: str = RUNNING,
        pid: int = 0,
        started_at: float = 0.0,
        restarts: int = 0,
        streak: int = 0,
        returncode: int | None = None,
        outcome: str = "",
        failed: bool = False,
        run_time: float = 0.0,
        peak_rss: int = 0,
        cpu_time: float = 0.0,
        restart_at: float | None = None,
        signals: list[int] | None = None,
    ) -> None:
        self.label = label
        self.spec = spec
        self.state = state
        self.pid = pid
        self.started_at = started_at
        self.restarts = restarts
        # Quick exits in a row: the exponent of the crash-loop backoff.
        self.streak = streak
        self.returncode = returncode
        self.outcome = outcome
        self.failed = failed
        self.run_time = run_time
        self.peak_rss = peak_rss
        self.cpu_time = cpu_time
        self.restart_at = restart_at
        self.signals: list[int] = [] if signals is None else signals

    def __repr__(self) -> str:
        return (
            f"ProcessRecord(label={self.label!r}, state={self.state!r}, pid={self.pid},"
            f" restarts={self.restarts}, outcome={self.outcome!r})"
        )


def respawn_delay(policy: RespawnPolicy, streak: int) -> float:
    """The wait before the next start: ``delay``, then growing by ``backoff`` per quick exit.

    Capped at ``max_delay`` (or ``delay`` if that is larger).
    """
    if streak <= 0 or policy.backoff <= 1.0:
        return policy.delay
    base = policy.delay or BACKOFF_BASE
    cap = max(policy.max_delay, policy.delay)
    return min(base * policy.backoff ** min(streak, 64), cap)


class Supervisor:
    """Runs a Plan. Seams (printer, clock, guard, run id) are constructor arguments.

    ``adopt``: become the subreaper and end every descendant at shutdown; an embedder with
    children of its own passes False (the run's processes are still found by their marker).
    ``stray_grace``: seconds between SIGTERM and SIGKILL for a stray descendant.
    """

    def __init__(
        self,
        plan: Plan,
        printer: Printer,
        *,
        options: ResolveOptions | None = None,
        labels: LabelCounter | None = None,
        clock: Callable[[], float] = time.monotonic,
        install_signals: bool = True,
        guard: guards.Guard | None = None,
        run_id: str | None = None,
        adopt: bool = True,
        stray_grace: float = STRAY_GRACE,
    ) -> None:
        self.plan = plan
        self.printer = printer
        self.options = options or ResolveOptions()
        self.labels = labels or LabelCounter()
        self.clock = clock
        self.install_signals = install_signals
        self.guard = guard
        self.run_id = run_id or guards.new_run_id()
        self.adopt = adopt
        self.stray_grace = stray_grace
        self.selector = selectors.DefaultSelector()
        self.by_pid: dict[int, Process] = {}
        self.processes: list[Process] = []
        self.lingering: list[Process] = []
        self.handlers: list[AddHandler] = []
        self.records: dict[str, ProcessRecord] = {}
        self._timers: list[_Timer] = []
        self._seq = itertools.count()
        self._signals: list[int] = []
        self._index = itertools.count()
        self.shutting_down = False
        self._held: set[Process] = set()
        self.shutdown_reason = ""
        self.exit_code = EXIT_OK
        self._stop_presses = 0
        self._wake_r = self._wake_w = -1
        self._old_wakeup = -1
        self._old_handlers: dict[int, Any] = {}
        self._subreaper = False
        self._kill_now = False
        self._marker_env = {guards.MARKER: self.run_id}
        self._core: tuple[str, bool, int] | None = None
        self.event_hooks: dict[type, Callable[[Any], None]] = {}
        self.listeners: list[Callable[[str, Process], None]] = []
        self._stray_seen: dict[int, float] = {}
        self._stray_signalled: set[tuple[int, int]] = set()
        # A child had exited before the subreaper was set: its orphans may have gone to init,
        # where only the marker scan finds them.
        self._escaped = False
        # Output flow: the terminal fd selected for writability, and the pipes not read while
        # the terminal is behind (fd -> process).
        self._out_fd: int | None = None
        self._out_unselectable: set[int] = set()
        self._paused: dict[int, Process] = {}

    # --- the loop ------------------------------------------------------------------------------

    def run(self) -> int:
        self._setup_signals()
        try:
            for warning in self.plan.warnings:
                self.printer.message("WARNING", "launch", warning)
            self.execute(self.plan.steps)
            if self.guard is not None:
                self.guard.flush()  # the first spawns' groups, in one write
            # After the first spawns, not before: ctypes costs milliseconds and the first child
            # should not wait for it. An orphan from that window is still found by its marker.
            if self.adopt:
                self._set_subreaper(True)
                self._escaped = self._a_child_has_exited()
            while not self._finished():
                self._loop_once()
            if self.guard is not None:
                # Everything of the run has ended: the guard may leave while we tidy up.
                self.guard.dismiss()
        except BaseException:
            self._emergency_stop()
            raise
        finally:
            if self._subreaper:
                self._set_subreaper(False)
            self._restore_signals()
            self.printer.flush()
        return self.exit_code

    def _loop_once(self) -> None:
        timeout = self._next_timeout()
        if timeout is None or timeout > 0:
            self.printer.flush()
        if self.guard is not None and self.guard.pending:
            self.guard.flush()  # this turn's +pgid/-pgid lines, in one write
        if self._watch_output() or self._paused:
            # The terminal cannot be selected on, or children wait for it: look again soon
            # (a stalled reader must not hold them longer than the Screen's stall time).
            timeout = POLL if timeout is None else min(timeout, POLL)
        ready = self.selector.select(timeout)
        for key, _ in ready:
            key.data(key.fd)
        self._handle_signals()
        self._run_due_timers()

    # --- output flow ----------------------------------------------------------------------------

    def _watch_output(self) -> bool:
        """Select the terminal for writability while output waits; resume held pipes.

        True when output waits on a terminal that cannot be selected on (then the loop polls).
        """
        fd = self.printer.waiting_fd()
        if fd != self._out_fd:
            if self._out_fd is not None:
                self.selector.unregister(self._out_fd)
                self._out_fd = None
            if fd is not None and fd not in self._out_unselectable:
                try:
                    self.selector.register(fd, selectors.EVENT_WRITE, self._writable)
                    self._out_fd = fd
                except (OSError, ValueError, KeyError):
                    # A regular file or /dev/null (never blocks), a closed fd, or one already
                    # in the selector: flushed each turn instead.
                    self._out_unselectable.add(fd)
        if self._paused and not self.printer.holding():
            self._resume_reading()
        if fd is None:
            return self.printer.blocked()  # a screen of another kind (a test's) with a backlog
        return fd != self._out_fd

    def _writable(self, fd: int) -> None:
        self.printer.flush_screen()
        if self._paused and not self.printer.holding():
            self._resume_reading()

    def _resume_reading(self) -> None:
        """The terminal caught up (or stalled): read the held pipes again."""
        paused, self._paused = self._paused, {}
        for fd, process in paused.items():
            if fd in process.streams:
                self._select(process, fd)

    def _select(self, process: Process, fd: int) -> None:
        self.selector.register(
            fd, selectors.EVENT_READ, lambda fd, p=process: self._readable(p, fd)
        )

    def _close_stream(self, process: Process, fd: int) -> None:
        """Stop watching a pipe (in the selector, or held) and close it."""
        if self._paused.pop(fd, None) is None:
            self.selector.unregister(fd)
        process.close_stream(fd)

    def _finished(self) -> bool:
        if any(p.running for p in self.processes):
            return False
        if not self.shutting_down:
            if any(t.keeps_alive and not t.cancelled for t in self._timers):
                return False
            # Idle: nothing runs and nothing is pending, as ROS 2's idle shutdown.
            self.begin_shutdown("idle")
        if self._lingering_pending():
            return False
        if self._strays_pending():
            return False
        for process in self.processes:
            for fd in list(process.streams):
                self._read(process, fd)
                if fd in process.streams:
                    self._close_stream(process, fd)
        return True

    def _lingering_pending(self) -> bool:
        """Groups whose leader is gone but a member lives on (a grandchild in the same group)."""
        for process in list(self.lingering):
            if not process.check_group():
                self.lingering.remove(process)
                if self.guard is not None:
                    self.guard.forget(process.pid)
        return bool(self.lingering)

    def _strays_pending(self) -> bool:
        """Processes of the run outside every group we watch: end them; True while any lives.

        A stray is a descendant (we are its subreaper) or a process carrying the run's marker
        (it escaped before the subreaper was set, or was re-parented elsewhere). SIGTERM and
        SIGCONT first, SIGKILL after ``stray_grace`` (at once after a second Ctrl-C).
        """
        strays = self._strays()
        if not strays:
            return False
        now = self.clock()
        for proc in strays:
            first = self._stray_seen.setdefault(proc.pid, now)
            late = self._kill_now or now - first >= self.stray_grace
            sig = signal.SIGKILL if late else signal.SIGTERM
            if (proc.pid, sig) in self._stray_signalled:
                continue
            self._stray_signalled.add((proc.pid, sig))
            name = _comm(proc.pid)
            try:
                os.kill(proc.pid, sig)
                if sig == signal.SIGTERM:
                    os.kill(proc.pid, signal.SIGCONT)
            except OSError:
                continue
            self.printer.message(
                "WARNING",
                "launch",
                f"ending stray descendant {name} [pid {proc.pid}] with {signal_name(sig)}",
            )
        return True

    def _strays(self, *, thorough: bool = False) -> list[guards.ProcInfo]:
        """Processes of the run outside our own children: descendants, and marked ones.

        The walk down our process tree is cheap and, as subreaper, sees every descendant that
        was orphaned after the subreaper was set. The marker scan reads every process's
        environment (~ms), so it is made only when something may have escaped the walk.
        """
        found: dict[int, guards.ProcInfo] = {}
        if self._subreaper or self.adopt:
            found.update((p.pid, p) for p in guards.tree(os.getpid()))
        if thorough or not self._subreaper or self._escaped:
            found.update((p.pid, p) for p in guards.marked(self.run_id))
        if self.guard is not None:
            found.pop(self.guard.pid, None)
        for pid in self.by_pid:  # our own children are the ladder's business
            found.pop(pid, None)
        return list(found.values())

    def _next_timeout(self) -> float | None:
        while self._timers and self._timers[0].cancelled:
            heapq.heappop(self._timers)
        polling = self.shutting_down and bool(self.lingering or self._stray_seen)
        if not self._timers:
            return POLL if polling else None
        delay = max(0.0, self._timers[0].when - self.clock())
        return min(delay, POLL) if polling else delay

    def schedule(
        self,
        delay: float,
        callback: Callable[[], None],
        *,
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> _Timer:
        """Call ``callback`` from the loop after ``delay`` seconds.

        ``keeps_alive`` False: the timer alone does not keep an idle launch running (a status
        refresh); ``cancel_on_shutdown`` False: it still fires while shutting down (the ladder).
        """
        timer = _Timer(
            self.clock() + delay, next(self._seq), callback, keeps_alive, cancel_on_shutdown
        )
        heapq.heappush(self._timers, timer)
        return timer

    def _run_due_timers(self) -> None:
        now = self.clock()
        while self._timers and self._timers[0].when <= now:
            timer = heapq.heappop(self._timers)
            if not timer.cancelled:
                timer.cancelled = True
                timer.callback()

    # --- plan steps ------------------------------------------------------------------------------

    def execute(self, steps: list[Step]) -> None:
        for step in steps:
            if isinstance(step, Spawn) and step.spec is not None:
                self.start(step.spec)
            elif isinstance(step, Log):
                self.printer.message(step.level, step.source, step.message)
            elif isinstance(step, StartTimer) and step.body is not None:
                body = step.body
                self.schedule(
                    step.period,
                    lambda body=body: self.fire(body, None),  # type: ignore[misc]
                    cancel_on_shutdown=step.cancel_on_shutdown,
                )
            elif isinstance(step, AddHandler):
                self.handlers.insert(0, step)  # newest first, as ROS 2
            elif isinstance(step, RemoveHandler):
                self.handlers = [h for h in self.handlers if h.handler is not step.handler]
            elif isinstance(step, RequestShutdown):
                self.begin_shutdown(step.reason)
            elif isinstance(step, EmitEvent):
                self.emit(step.event)

    def fire(self, body: Deferred, event: Any) -> None:
        """Resolve deferred entities now (timer, handler, on_exit) and run what they give."""
        try:
            plan = resolve_deferred(body, labels=self.labels, options=self.options, event=event)
        except MlaunchError as e:
            self.printer.message("ERROR", "launch", str(e))
            self.exit_code = max(self.exit_code, EXIT_LAUNCH_ERROR)
            self.begin_shutdown("an event handler failed")
            return
        for warning in plan.warnings:
            self.printer.message("WARNING", "launch", warning)
        self.execute(plan.steps)

    def _dispatch(self, kind: str, process: Process | None, event: Any) -> None:
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
                self.fire(handler.body, event)

    def emit(self, event: Any) -> None:
        """Events a launch file emits: ShutdownProcess, SignalProcess, or a hook's (lifecycle)."""
        if isinstance(event, ev.Shutdown):
            self.begin_shutdown(event.reason)
            return
        if isinstance(event, ev.ShutdownProcess):
            for p in self._matching(event.process_matcher):
                self.stop(p)
            return
        if isinstance(event, ev.SignalProcess):
            for p in self._matching(event.process_matcher):
                p.signal_group(int(event.signal_number))
            return
        hook = self.event_hooks.get(type(event))
        if hook is None:
            self.printer.message(
                "WARNING",
                "launch",
                f"event {type(event).__name__} has no handler in mlaunch; ignored",
            )
            return
        hook(event)

    def _matching(self, matcher: Callable[[Any], bool] | None) -> list[Process]:
        return [p for p in self.processes if p.running and (matcher is None or matcher(p))]

    # --- processes ---------------------------------------------------------------------------

    def start(self, spec: ProcessSpec, restarts: int = 0) -> Process | None:
        if self.shutting_down:
            self.printer.message("WARNING", spec.label, "not started: the launch is shutting down")
            return None
        process = Process(spec, index=next(self._index), restarts=restarts)
        self.printer.register(spec.label, process.index)
        record = self.records.get(spec.label)
        if record is None:
            record = self.records[spec.label] = ProcessRecord(spec.label, spec)
        record.restarts, record.restart_at = restarts, None
        if spec.standin and restarts == 0:
            self.printer.message(
                "INFO", spec.label, f"{spec.standin}: not installed, using mlaunch's stand-in"
            )
        try:
            process.spawn(self.clock, self._marker_env)
        except OSError as e:
            reason = e.strerror or str(e)
            self.printer.message("ERROR", spec.label, f"failed to start {spec.argv[0]!r}: {reason}")
            process.returncode = 127
            self.processes.append(process)
            record.state, record.failed, record.returncode = FAILED, True, 127
            record.outcome = f"failed to start: {reason}"
            self._after_exit(process)
            return process
        if self.guard is not None:
            self.guard.watch(process.pid, spec.sigkill_timeout)
        self.processes.append(process)
        self.by_pid[process.pid] = process
        record.state, record.pid, record.started_at = RUNNING, process.pid, process.started_at
        for fd in process.streams:
            self._select(process, fd)
        self.printer.message("INFO", spec.label, f"process started with pid [{process.pid}]")
        self._notify("started", process)
        self._dispatch(
            "process_start",
            process,
            ev.ProcessStarted(
                action=spec.action,
                name=spec.label,
                cmd=list(spec.argv),
                cwd=spec.cwd,
                env=spec.env,
                pid=process.pid,
            ),
        )
        return process

    def _readable(self, process: Process, fd: int) -> None:
        """A child's pipe has data: read it, unless the terminal is too far behind."""
        if self.printer.holding():
            # Leave it in the pipe: the child blocks on a full pipe until the terminal catches
            # up. Out of the selector meanwhile, or every turn would find it ready again.
            if fd in process.streams:
                self.selector.unregister(fd)
                self._paused[fd] = process
            return
        self._read(process, fd)

    def _read(self, process: Process, fd: int) -> None:
        stream = process.streams.get(fd)
        if stream is None:
            return
        data, eof = process.read(fd)
        if data:
            self._deliver(process, stream.name, data)
        if eof:
            self._close_stream(process, fd)

    def _deliver(self, process: Process, stream: str, data: bytes) -> None:
        """Complete lines of a child: to the printer, then to OnProcessIO handlers."""
        self.printer.output(process.label, stream, process.spec.output, data)
        if self.handlers:
            self._io_event(process, stream, data)

    def _io_event(self, process: Process, stream: str, data: bytes) -> None:
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
                self.printer.message(
                    "ERROR",
                    "launch",
                    f"{where}: OnProcessIO callback failed: {type(e).__name__}: {e}",
                )
                self.exit_code = max(self.exit_code, EXIT_LAUNCH_ERROR)
                self.begin_shutdown("an event handler failed")
                return
            if result and handler.body is not None:
                body = handler.body
                self.fire(Deferred(list(result), body.context, body.origin), event)

    def _drain(self, process: Process) -> None:
        """Read what is left in a finished process's pipes before reporting its exit."""
        for fd in list(process.streams):
            for _ in range(64):
                if fd not in process.streams:
                    break
                data, eof = process.read(fd)
                if data:
                    self._deliver(process, process.streams[fd].name, data)
                if eof:
                    self._close_stream(process, fd)

    def _reap(self) -> None:
        while True:
            try:
                pid, status, rusage = os.wait4(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            process = self.by_pid.pop(pid, None)
            if process is None:
                continue  # an orphaned grandchild we adopted as subreaper, or the guard
            process.reaped(status, self.clock, rusage)
            # Its last words first: what is still in the pipes, then the partial last line.
            self._drain(process)
            self._flush_partial(process)
            if process.check_group():
                self.lingering.append(process)
            elif self.guard is not None:
                self.guard.forget(process.pid)
            self._record_exit(process)
            self._after_exit(process)

    def _flush_partial(self, process: Process) -> None:
        """A child that died mid-line: print what it had (a grandchild may keep the pipe open)."""
        for stream in process.streams.values():
            if stream.partial:
                data, stream.partial = stream.partial + b"\n", b""
                self._deliver(process, stream.name, data)

    def _record_exit(self, process: Process) -> None:
        record = self.records[process.label]
        code = process.returncode if process.returncode is not None else 0
        record.returncode = code
        record.run_time += max(0.0, process.ended_at - process.started_at)
        record.peak_rss = max(record.peak_rss, process.peak_rss)
        record.cpu_time += process.cpu_time
        record.signals.extend(process.signals_sent)
        record.failed = False
        if process.stopping:
            record.outcome = _stopped_outcome(process, code)
        elif code == 0:
            record.outcome = "finished cleanly"
        else:
            record.failed = True
            record.outcome = describe_status(code) + (
                " (core dumped)" if process.core_dumped else ""
            )
        record.state = FAILED if record.failed else FINISHED

    def _after_exit(self, process: Process) -> None:
        spec = process.spec
        code = process.returncode if process.returncode is not None else 0
        self._report_exit(process, code)
        self._notify("exited", process)
        if spec.required and not process.stopping:
            # A required process decides the run: it ends it, and its failure is the run's.
            # First, so the shutdown names it (its on_exit=Shutdown() then has nothing to do).
            if code != 0:
                self.exit_code = max(self.exit_code, EXIT_REQUIRED_FAILED)
            self.begin_shutdown(f"required process {spec.label} {describe_status(code)}")
        event = ev.ProcessExited(
            action=spec.action,
            name=spec.label,
            cmd=list(spec.argv),
            cwd=spec.cwd,
            env=spec.env,
            pid=process.pid,
            returncode=code,
        )
        self._dispatch("process_exit", process, event)
        if spec.on_exit is not None:
            self.fire(spec.on_exit, event)
        self._maybe_respawn(process, code)

    def _report_exit(self, process: Process, code: int) -> None:
        label, pid = process.label, process.pid
        if not pid:
            return  # never started: "failed to start" said it all
        if code == 0:
            self.printer.message("INFO", label, f"process has finished cleanly [pid {pid}]")
            return
        if process.stopping and code < 0 and -code in process.signals_sent:
            self.printer.message(
                "INFO", label, f"process stopped by {signal_name(-code)} [pid {pid}]"
            )
            return
        what = describe_status(code)
        if process.core_dumped:
            what += " (core dumped)"
        # ROS 2's format; a newline inside an argument (python -c code) is shown escaped so that
        # the message stays one line.
        cmd = " ".join(process.argv).replace("\n", "\\n")
        self.printer.message(
            "ERROR", label, f"process has died [pid {pid}, exit code {code}, cmd '{cmd}']: {what}"
        )
        if code < 0 and not process.stopping:
            hint = self._core_hint(process, -code)
            if hint:
                self.printer.message("INFO", label, hint)

    def _core_hint(self, process: Process, signal_number: int) -> str | None:
        if self._core is None:
            pattern, uses_pid = read_core_pattern()
            self._core = (pattern, uses_pid, core_limit())
        pattern, uses_pid, limit = self._core
        spec = process.spec
        return core_dump_hint(
            pid=process.pid,
            signal_number=signal_number,
            dumped=process.core_dumped,
            executable="/bin/sh" if spec.shell else spec.argv[0],
            cwd=spec.cwd or os.getcwd(),
            pattern=pattern,
            uses_pid=uses_pid,
            limit=limit,
        )

    def _maybe_respawn(self, process: Process, code: int) -> None:
        policy = process.spec.respawn
        if self.shutting_down or process.stopping or policy.mode == "never":
            return
        if policy.mode == "on-failure" and code == 0:
            return
        record = self.records[process.label]
        if 0 <= policy.max_retries <= record.restarts:
            record.state = GAVE_UP
            record.outcome = f"gave up after {record.restarts} restarts: {record.outcome}"
            self.printer.message(
                "ERROR",
                process.label,
                f"giving up after {record.restarts} restarts ({describe_status(code)})",
            )
            return
        if process.ended_at - process.started_at >= STABLE_UPTIME:
            record.streak = 0  # it ran well for a while: not a crash loop
        delay = respawn_delay(policy, record.streak)
        record.streak += 1
        attempt = record.restarts + 1
        limit = "" if policy.max_retries < 0 else f"/{policy.max_retries}"
        self.printer.message(
            "WARNING",
            process.label,
            f"{describe_status(code)}, restart {attempt}{limit} in {_seconds(delay)} s",
        )
        record.state, record.restart_at = RESTARTING, self.clock() + delay
        self.schedule(delay, lambda: self._respawn(process, attempt))

    def _respawn(self, old: Process, attempt: int) -> None:
        """Start the same spec again (same argv, label, temp files); forget the old instance."""
        if not old.streams and old not in self.lingering and old in self.processes:
            self.processes.remove(old)  # a crash loop must not grow the list forever
        self.start(old.spec, restarts=attempt)

    # --- stopping ----------------------------------------------------------------------------

    def begin_shutdown(self, reason: str, *, due_to_signal: int | None = None) -> None:
        if self.shutting_down:
            return
        self.shutting_down = True
        self.shutdown_reason = reason
        if reason != "idle":
            self.printer.message("INFO", "launch", f"shutting down: {reason}")
        for timer in self._timers:
            if timer.cancel_on_shutdown:
                timer.cancelled = True  # pending respawns and TimerActions included
        for record in self.records.values():
            if record.state == RESTARTING:
                record.state, record.restart_at = (FAILED if record.failed else FINISHED), None
        self._dispatch(
            "shutdown",
            None,
            ev.Shutdown(reason=reason, due_to_sigint=due_to_signal == signal.SIGINT),
        )
        for process in self.processes:
            if process.running and process not in self._held:
                self.stop(process)
        for process in self.lingering:
            if process.check_group() and not process.stopping:
                self.stop(process)

    def hold_stop(self, process: Process) -> None:
        """Keep ``process`` out of the stop ladder until ``release_stop`` (or a second Ctrl-C).

        For work that must happen while a process still runs at shutdown, such as deactivating
        a lifecycle node before it is signalled. Call it from a shutdown handler: the ladder
        starts for every process not held right after those handlers run.
        """
        self._held.add(process)

    def release_stop(self, process: Process) -> None:
        """Hand a held process to the stop ladder (now, if the launch is shutting down)."""
        self._held.discard(process)
        if self.shutting_down and process.running:
            self.stop(process)

    def stop(self, process: Process) -> None:
        """The ladder for one process group: SIGINT, SIGTERM, SIGKILL, each after its timeout."""
        if process.stopping:
            return
        process.stopping = True
        if process.running:
            self.records[process.label].state = STOPPING
        spec = process.spec
        if not process.signal_group(signal.SIGINT, wake=True):
            return

        def escalate(sig: int, waited: float, next_step: Callable[[], None] | None) -> None:
            if not (process.running or process.check_group()):
                return
            self.printer.message(
                "WARNING",
                process.label,
                f"failed to terminate {waited:g} s after {signal_name(process.signals_sent[-1])},"
                f" escalating to {signal_name(sig)} [pid {process.pid}]",
            )
            process.signal_group(sig, wake=True)
            if next_step is not None:
                next_step()

        def to_kill() -> None:
            self.schedule(
                spec.sigkill_timeout,
                lambda: escalate(signal.SIGKILL, spec.sigkill_timeout, None),
                cancel_on_shutdown=False,
            )

        self.schedule(
            spec.sigterm_timeout,
            lambda: escalate(signal.SIGTERM, spec.sigterm_timeout, to_kill),
            cancel_on_shutdown=False,
        )

    def kill_everything(self) -> None:
        """A second Ctrl-C: SIGKILL every group and every stray at once."""
        self.printer.message("WARNING", "launch", "stopping now: SIGKILL to every process")
        self._kill_now = True
        for process in self.processes + self.lingering:
            if process.running or process.check_group():
                process.stopping = True
                process.signal_group(signal.SIGKILL)
        self.begin_shutdown("killed")

    def _emergency_stop(self) -> None:
        """The loop itself failed: kill everything we know of before the error propagates."""
        try:
            for process in self.processes + self.lingering:
                if process.running or process.check_group():
                    process.signal_group(signal.SIGKILL)
            for proc in self._strays(thorough=True):
                try:
                    os.kill(proc.pid, signal.SIGKILL)
                except OSError:
                    pass
            self._reap()
        except Exception:
            pass  # the original error is the one worth reporting

    # --- signals -----------------------------------------------------------------------------

    def _setup_signals(self) -> None:
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self.selector.register(self._wake_r, selectors.EVENT_READ, self._drain_wakeup)
        # What was there before is put back at the end (an embedder may have its own).
        self._old_wakeup = signal.set_wakeup_fd(self._wake_w, warn_on_full_buffer=False)
        ours = (*STOP_SIGNALS, signal.SIGCHLD) if self.install_signals else (signal.SIGCHLD,)
        self._old_handlers = {sig: signal.signal(sig, self._record_signal) for sig in ours}

    def _record_signal(self, signum: int, frame: object) -> None:
        self._signals.append(signum)

    def _drain_wakeup(self, fd: int) -> None:
        try:
            while os.read(fd, 4096):
                pass
        except BlockingIOError:
            pass

    def _handle_signals(self) -> None:
        while self._signals:
            sig = self._signals.pop(0)
            if sig == signal.SIGCHLD:
                self._reap()
                continue
            self._stop_presses += 1
            if self._stop_presses == 1:
                self.exit_code = max(self.exit_code, 128 + sig)
                self.printer.message(
                    "WARNING",
                    "launch",
                    f"user interrupted with {signal_name(sig)}; stopping (again to kill)",
                )
                self.begin_shutdown(f"{signal_name(sig)} received", due_to_signal=sig)
            else:
                self.kill_everything()
        self._reap()

    def _restore_signals(self) -> None:
        for sig, handler in self._old_handlers.items():
            signal.signal(sig, handler if handler is not None else signal.SIG_DFL)
        signal.set_wakeup_fd(self._old_wakeup)
        self.selector.close()
        self._out_fd = None
        for fd in (self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass

    def _a_child_has_exited(self) -> bool:
        """Whether a child is already a zombie (exited before we became subreaper)."""
        try:
            info = os.waitid(os.P_ALL, 0, os.WEXITED | os.WNOHANG | os.WNOWAIT)
        except (ChildProcessError, OSError):
            return False
        return info is not None

    def _set_subreaper(self, on: bool) -> None:
        """As subreaper, orphaned descendants are re-parented to mlaunch, not to init."""
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            ok = libc.prctl(PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0) == 0
        except (OSError, AttributeError):
            ok = False
        self._subreaper = ok and on

    def _notify(self, what: str, process: Process) -> None:
        for listener in self.listeners:
            listener(what, process)


def _seconds(value: float) -> str:
    """``4.0``, ``0.5``, ``0.05``: one decimal unless that would round a short delay away."""
    return f"{value:.2f}" if 0 < value < 0.1 else f"{value:.1f}"


def _stopped_outcome(process: Process, code: int) -> str:
    if code < 0 and -code in process.signals_sent:
        return f"stopped by {signal_name(-code)}"
    if code == 0:
        return "stopped, exited cleanly"
    return f"stopped, {describe_status(code)}"


def _comm(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/comm") as f:
            return f.read().strip()
    except OSError:
        return "?"
