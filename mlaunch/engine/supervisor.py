"""run(plan) -> exit code: start processes, stream their output, fire triggers, stop everything.

One thread, one ``selectors`` loop. Signal handlers only record the signal (and wake the loop
through ``signal.set_wakeup_fd``); the loop acts on them. Every child runs in its own session, so
the stop ladder (mlaunch.engine.ladder) reaches its whole process group.

The supervisor writes no words. It emits a record of everything that happens on its
RecordStream (mlaunch.plan.records) and acts on policy: this module is where a process's exit
becomes, in order, an ``Exited`` record (the printer turns it into the log line, the launch
file's handlers fire on it, lifecycle driving and smoke checks see it), the required-process
shutdown, and the respawn decision (``_exited``). Its own reaction to the stream is starting the
stop ladder (``_react``); launch's own events (ShutdownProcess ...) are mlaunch.engine.handlers'.

Nothing is left behind: descendants that leave their group are found and ended at shutdown
(mlaunch.engine.strays); a guard process (mlaunch.engine.guard, a constructor seam) ends the run if
mlaunch itself is killed; if the loop itself fails, every group is killed before the error
propagates.

The children's pipes and the terminal share the loop's selector (mlaunch.engine.pipes): a slow
terminal holds the children's pipes unread instead of losing lines. The per-label ProcessState
(mlaunch.engine.process_state) is what the status view and the exit summary read. Signals are
recorded by mlaunch.engine.signals, timers are mlaunch.engine.timers, the respawn policy is
mlaunch.engine.respawn, the launch file's event handlers are mlaunch.engine.handlers, and the
shutdown is its ``Stopping`` (mlaunch.engine.stopping), the respawns its ``Respawns``, and the
plan's steps are carried out by its ``Executor`` (mlaunch.engine.executor).
"""

from __future__ import annotations

import errno
import itertools
import selectors
import signal
import time
from collections.abc import Callable, Mapping
from types import MappingProxyType

from mlaunch.engine import fdlimit, proctable
from mlaunch.engine import guard as guards
from mlaunch.engine.executor import Executor
from mlaunch.engine.handlers import LaunchHandlers
from mlaunch.engine.ladder import StopLadder
from mlaunch.engine.output import Printer
from mlaunch.engine.pipes import Pipes
from mlaunch.engine.process import Process, describe_status, wait_child
from mlaunch.engine.process_state import RESTARTING, RUNNING, STOPPED, ProcessState
from mlaunch.engine.reactor import PartSelector, Reactor, RunRecords
from mlaunch.engine.respawn import Respawns
from mlaunch.engine.signals import SignalWatch
from mlaunch.engine.stopping import Stopping, handle_signals
from mlaunch.engine.strays import STRAY_GRACE, Strays, comm
from mlaunch.engine.timers import Timer, Timers
from mlaunch.plan.errors import EXIT_FAILURE, EXIT_INTERNAL, EXIT_OK
from mlaunch.plan.records import (
    Exited,
    FailedToStart,
    NotStarted,
    Output,
    Record,
    Said,
    Started,
    StoppingAll,
    StrayEnded,
)
from mlaunch.plan.steps import (
    AddHandler,
    Deferred,
    Plan,
    ProcessSpec,
    Step,
)
from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve_deferred

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Protocol

    from mlaunch.engine.cgroup import RunCgroup

    class PrestartedChild(Protocol):
        """A child started before the run (mlaunch.app.quick.Child)."""

        @property
        def pid(self) -> int: ...

        @property
        def fds(self) -> tuple[int, int, int]: ...

        @property
        def started_at(self) -> float: ...

        @property
        def how(self) -> str: ...

    class Prestarted(Protocol):
        """The children started before the run, for it to adopt (mlaunch.app.quick)."""

        def has(self, spec: ProcessSpec) -> bool: ...

        def take(self, spec: ProcessSpec, env: Mapping[str, str]) -> PrestartedChild | None: ...

        def abandon(self) -> None: ...


# How often the guard is told the groups of orphans re-parented to mlaunch (escaped daemons).
ADOPTED_POLL = 1.0
# How often the loop looks at lingering groups, strays and a blocked terminal while it waits.
POLL = 0.05


class Supervisor:
    """Runs a Plan. Seams (printer, clock, guard, run id) are constructor arguments.

    The printer is subscribed to ``events`` first (after the supervisor's own reactions), then
    the launch file's handlers; whatever else attaches to the run subscribes after them. The
    printer is also the terminal whose flow control the loop drives.

    ``adopt``: become the subreaper and end every descendant at shutdown; an embedder with
    children of its own passes False (the run's processes are still found by their marker).
    ``stray_grace``: seconds between SIGTERM and SIGKILL for a stray descendant.
    ``spawner(spec, index, restarts)``: makes the Process for a spec (``Process`` by default).
    ``gentle_on_error``: an exception out of the loop (an embedder's host raising from a signal
    handler of its own: a test runner's timeout) first stops everything through the stop ladder,
    the loop turning on; SIGKILL only for what that leaves or when the loop fails again.
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
        spawner: Callable[[ProcessSpec, int, int], Process] = Process,
        cgroup: RunCgroup | None = None,
        gentle_on_error: bool = False,
        prestarted: Prestarted | None = None,
    ) -> None:
        self.plan = plan
        # The plan's first processes, started before the supervisor was made (by the quick start,
        # or as soon as the plan was known: mlaunch.app.quick): adopted by start().
        self.prestarted = prestarted
        self.gentle_on_error = gentle_on_error
        # Subscribed below, and the terminal whose flow control the loop drives; parts are
        # handed the printer by the run (mlaunch.app.parts.Run), never through here.
        self._printer = printer
        self.options = options or ResolveOptions()
        self.labels = labels or LabelCounter()
        self.clock = clock
        self.guard = guard
        self.run_id = run_id or guards.new_run_id()
        # Makes the Process for a spec: remote machines plug in here (mlaunch.parts.remote).
        self.spawner = spawner
        # The loop's selector; parts register through ``selector``, which makes what they
        # register theirs (mlaunch.engine.reactor), the children's pipes and signals go here.
        self._selector = selectors.DefaultSelector()
        self.by_pid: dict[int, Process] = {}
        self.processes: list[Process] = []
        self.lingering: list[Process] = []
        self._adopted_groups: set[int] = set()  # groups of adopted orphans the guard watches
        self.states: dict[str, ProcessState] = {}
        self.timers = Timers(clock)
        self.signals = SignalWatch(install=install_signals)
        self.strays = Strays(
            self.run_id, adopt=adopt, grace=stray_grace, clock=clock, cgroup=cgroup
        )
        self.pipes = Pipes(self._selector, printer, self._deliver)
        self.launch_handlers = LaunchHandlers(self)
        self.records = RunRecords()
        # Its steps outlive the shutdown's cancellation of timers.
        self.ladder = StopLadder(
            lambda delay, step: self.timers.add(delay, step, cancel_on_shutdown=False),
            self.records.emit,
            self.states,
        )
        self.records.subscribe(self._react)
        self.records.subscribe(printer)
        self.records.subscribe(self.launch_handlers)
        # What attaches to the run from here on is a part, behind a wall (reactor.py).
        self.reactor = Reactor(self.records, self._selector, self.part_failed)
        self.records.reactor = self.reactor
        self.selector = PartSelector(self._selector, self.reactor)
        self._index = itertools.count()
        self.exit_code = EXIT_OK
        self.shutdown = Stopping(
            records=self.records,
            timers=self.timers,
            states=self.states,
            ladder=self.ladder,
            processes=self.processes,
            lingering=self.lingering,
            exit_status=self.exit_status,
        )
        self.respawns = Respawns(
            states=self.states,
            timers=self.timers,
            records=self.records,
            clock=clock,
            start=self.start,
            forget=self._forget,
        )
        self.executor = Executor(
            records=self.records,
            timers=self.timers,
            handlers=self.launch_handlers,
            shutdown=self.shutdown,
            signals=self.signals,
            start=self.start,
            running=lambda spec: self.prestarted is not None and self.prestarted.has(spec),
            resolve=lambda body, event, shutting_down: resolve_deferred(
                body,
                labels=self.labels,
                options=self.options,
                event=event,
                shutting_down=self.shutting_down if shutting_down is None else shutting_down,
            ),
            exit_status=self.exit_status,
        )
        self._marker_env = {proctable.MARKER: self.run_id}
        # Work attached parts do outside the loop (composable node loads): keeps the run alive.
        self._work: set[object] = set()

    # --- stopping (mlaunch.engine.stopping) ------------------------------------------------------

    @property
    def shutting_down(self) -> bool:
        return self.shutdown.active

    @property
    def shutdown_reason(self) -> str:
        return self.shutdown.reason

    def begin_shutdown(self, reason: str, *, due_to_signal: int | None = None) -> None:
        """Shut the launch down (``Stopping.begin``): ShutdownBegun, then StoppingAll."""
        self.shutdown.begin(reason, due_to_signal=due_to_signal)

    def hold_stop(self, process: Process) -> None:
        """Keep ``process`` out of the stop ladder until ``release_stop`` (``Stopping.hold``)."""
        self.shutdown.hold(process)

    def release_stop(self, process: Process) -> None:
        self.shutdown.release(process)

    def stop(self, process: Process) -> None:
        """The stop ladder for one process group (mlaunch.engine.ladder)."""
        self.ladder.stop(process)

    def kill_everything(self) -> None:
        """A second Ctrl-C: SIGKILL every group and every stray at once."""
        self.shutdown.kill_everything()

    def exit_status(self, code: int) -> None:
        """The run's exit status is at least ``code`` (a failure, an interruption)."""
        self.exit_code = max(self.exit_code, code)

    def _stop_after(self, error: BaseException) -> None:
        """Stop everything through the ladder, the loop turning as before, until the run is
        over; if the loop fails again meanwhile, ``_emergency_stop`` kills what is left."""
        try:
            self.begin_shutdown(f"the run was interrupted ({type(error).__name__})")
            while not self._finished():
                self._loop_once()
        except BaseException:
            pass  # the first error is the one worth reporting

    def _emergency_stop(self) -> None:
        """The loop itself failed: kill everything we know of before the error propagates."""
        try:
            for process in self.processes + self.lingering:
                if process.running or process.check_group():
                    process.signal_group(signal.SIGKILL)
            self.strays.kill_all(self.by_pid, self.guard.pid if self.guard is not None else None)
            self._reap()
        except Exception:
            pass  # the original error is the one worth reporting

    @property
    def process_states(self) -> Mapping[str, ProcessState]:
        """What the run knows of each label, read-only (the status view, the exit summary,
        runtime control and the smoke checks read it; only the supervisor writes it)."""
        return MappingProxyType(self.states)

    @property
    def handlers(self) -> list[AddHandler]:
        """The launch file's registered event handlers, newest first."""
        return self.launch_handlers.handlers

    # --- the loop ------------------------------------------------------------------------------

    def run(self) -> int:
        self.signals.start(self._selector)
        try:
            self.execute(self.plan.steps, self.plan.warnings)
            if self.prestarted is not None:
                self.prestarted.abandon()  # what the plan does not start (said), if anything
                self._reap()  # an adopted child that ended before SIGCHLD was watched
            if self.guard is not None:
                self.guard.flush()  # the first spawns' groups, in one write
            # After the first spawns, not before: ctypes costs milliseconds and the first child
            # should not wait for it. An orphan from that window is still found by its marker.
            self.strays.adopt_orphans()
            if self.guard is not None and self.strays.subreaper:
                self.timers.add(ADOPTED_POLL, self._watch_adopted, False, True)
            while not self._finished():
                self._loop_once()
            if self.guard is not None:
                # Everything of the run has ended: the guard may leave while we tidy up.
                self.guard.dismiss()
        except BaseException as error:
            if self.gentle_on_error:
                self._stop_after(error)
            self._emergency_stop()
            raise
        finally:
            self.strays.release()
            self.signals.stop()
            self._selector.close()
            self.pipes.forget_terminal()
            self._printer.flush()
        return self.exit_code

    def _loop_once(self) -> None:
        timeout = self._next_timeout()
        if timeout is None or timeout > 0:
            self._printer.flush()
        if self.guard is not None and self.guard.pending:
            self.guard.flush()  # this turn's +pgid/-pgid lines, in one write
        if self.pipes.before_wait() or self.signals.polling:
            timeout = POLL if timeout is None else min(timeout, POLL)
        ready = self._selector.select(timeout)
        for key, _ in ready:
            key.data(key.fd)
        handle_signals(self.signals.pending, self._reap, self.shutdown.pressed)
        self.timers.run_due()

    def _finished(self) -> bool:
        if any(p.running for p in self.processes):
            return False
        if not self.shutting_down:
            if self.timers.keep_alive() or self._work:
                return False
            if any(r.state == STOPPED for r in self.states.values()):
                return False  # stopped by the user, who may start it again: not idle
            # Idle: nothing runs and nothing is pending, as ROS 2's idle shutdown.
            self.begin_shutdown("idle")
        if self._lingering_pending() or self.timers.hold_shutdown():
            return False
        if self._strays_pending():
            return False
        for process in self.processes:
            self.pipes.close_all(process)
        return True

    def busy(self, work: object) -> None:
        """``work`` (a hashable token) of an attached part, such as a composable node load
        waiting for its container, keeps an otherwise idle launch running until
        ``done(work)``, as launch's completion futures do; a shutdown does not wait for it."""
        self._work.add(work)

    def done(self, work: object) -> None:
        self._work.discard(work)

    def _lingering_pending(self) -> bool:
        """Groups whose leader is gone but a member lives on (a grandchild in the same group)."""
        for process in list(self.lingering):
            if not process.check_group():
                self.lingering.remove(process)
                if self.guard is not None:
                    self.guard.forget(process.pid)
        return bool(self.lingering)

    def _strays_pending(self) -> bool:
        """Processes of the run outside every group we watch: end them; True while any lives."""
        skip = self.guard.pid if self.guard is not None else None
        alive, sent = self.strays.sweep(self.by_pid, skip, now_kill=self.shutdown.kill_now)
        for name, pid, sig in sent:
            self.records.emit(StrayEnded(name, pid, sig))
        return alive

    def _next_timeout(self) -> float | None:
        polling = self.shutting_down and bool(self.lingering or self.strays.seen)
        delay = self.timers.next_delay()
        if delay is None:
            return POLL if polling else None
        return min(delay, POLL) if polling else delay

    def schedule(
        self,
        delay: float,
        callback: Callable[[], object],
        *,
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> Timer:
        """Call ``callback`` from the loop after ``delay`` seconds (a part's, when a part asks).

        ``keeps_alive`` False: the timer alone does not keep an idle launch running (a status
        refresh); ``cancel_on_shutdown`` False: it still fires while shutting down (the ladder).
        """
        callback = self.reactor.own(callback)
        return self.timers.add(delay, callback, keeps_alive, cancel_on_shutdown)

    def part_failed(self, name: str, error: BaseException, essential: bool) -> None:
        """An attached part raised (mlaunch.engine.reactor detached it): say so in one line;
        a part the run cannot go on without ends it through the stop ladder (exit status 70)."""
        text = f"{name} failed and was detached: {type(error).__name__}: {error}"
        if essential:
            text += "; the run cannot go on without it"
            self.exit_status(EXIT_INTERNAL)
        self.records.emit(Said("ERROR", "launch", text))
        if essential:
            self.begin_shutdown(f"{name} failed")

    # --- plan steps (mlaunch.engine.executor) -----------------------------------------------

    def execute(self, steps: list[Step], warnings: list[str] | tuple[str, ...] = ()) -> None:
        """Carry out a visited description's steps (``Executor.execute``)."""
        self.executor.execute(steps, warnings)

    def fire(self, body: Deferred, event: object, shutting_down: bool | None = None) -> None:
        """Resolve deferred entities now (timer, handler, on_exit) and run what they give;
        ``shutting_down``: what the handlers of ``event`` see (None: whether the run is now)."""
        self.executor.fire(body, event, shutting_down)

    def handler_failed(self, message: str) -> None:
        """A handler of the launch file failed: say where, then shut down (exit status 2)."""
        self.executor.handler_failed(message)

    def _react(self, record: Record) -> None:
        """The supervisor's own subscription: the stop ladder begins at StoppingAll."""
        if isinstance(record, StoppingAll) and not record.kill:
            self.shutdown.stop_all()

    # --- processes ---------------------------------------------------------------------------

    def start(self, spec: ProcessSpec, restarts: int = 0) -> Process | None:
        child = None
        if self.prestarted is not None and not restarts:
            child = self.prestarted.take(spec, self._marker_env)
        if self.shutting_down and child is None:
            self.records.emit(NotStarted(spec))
            return None
        if spec.prepare is not None:  # a stand-in's page keeps its port on a restart
            spec.prepare(spec)
        process = self.spawner(spec, next(self._index), restarts)
        record = self.states.get(spec.label)
        if record is None:
            record = self.states[spec.label] = ProcessState(spec.label, spec)
        record.restarts, record.restart_at = restarts, None
        try:
            if child is not None:
                process.adopt(child.pid, child.fds, child.started_at)
                said = f"{spec.label} (pid {child.pid}) was started {child.how}; adopted"
                self.records.emit(Said("DEBUG", "launch", said))
            else:
                self._spawn(process)
        except OSError as e:
            reason = e.strerror or str(e)
            process.returncode = 127
            self.processes.append(process)
            record.failed_to_start(reason)
            self.records.hold()
            try:
                self.records.emit(FailedToStart(process, reason))
                self._exited(process)
            finally:
                self.records.release()
            return process
        if self.guard is not None:
            self.guard.watch(process.pid, spec.sigkill_timeout)
        self.processes.append(process)
        self.by_pid[process.pid] = process
        record.state, record.pid, record.started_at = RUNNING, process.pid, process.started_at
        self.pipes.watch(process)
        self.records.emit(Started(process))
        return process

    def _spawn(self, process: Process) -> None:
        try:
            process.spawn(self.clock, self._marker_env)
        except OSError as e:
            if e.errno != errno.EMFILE or not fdlimit.limit().make_room():
                raise
            process.spawn(self.clock, self._marker_env)  # once more, with a higher limit

    def _deliver(self, process: Process, stream: str, data: bytes) -> None:
        """Complete lines of a child, onto the stream (the printer, then OnProcessIO handlers)."""
        self.records.emit(Output(process, stream, data))

    def _reap(self) -> None:
        # A subreaper waits for any child (adopted orphans too); an embedder's supervisor only
        # for its own, so it never takes the exit of its host's children or of another run's
        # (two LaunchServices on threads hung, each waiting for a child the other had reaped).
        mine = None if self.strays.adopt else self.by_pid
        while True:
            pid, status, rusage = wait_child(mine)
            if pid == 0:
                return
            process = self.by_pid.pop(pid, None)
            if process is None:
                continue  # an orphaned grandchild we adopted as subreaper, or the guard
            process.reaped(status, self.clock, rusage)
            # One record after another, handled once all are queued: its last words first
            # (what is still in the pipes, then the partial last line), then its exit.
            self.records.hold()
            try:
                self.pipes.drain(process)
                if process.check_group():
                    self.lingering.append(process)
                elif self.guard is not None:
                    self.guard.forget(process.pid)
                self.states[process.label].ended(process)
                self._exited(process)
                if process in self.lingering and self._replaced(process):
                    self._end_group(process)
            finally:
                self.records.release()

    def _watch_adopted(self) -> None:
        """Tell the guard the groups of orphans re-parented to mlaunch, every ``ADOPTED_POLL``.

        A daemon that double-forks, clears its environment and moves itself out of the run's
        cgroup carries nothing the guard could find it by after ``kill -9`` of mlaunch; while
        mlaunch lives it is mlaunch's child (the subreaper's), so its group is watched too.
        """
        guard = self.guard
        if guard is None or self.shutting_down:
            return
        watched = {p.pid for p in self.processes} | {p.pid for p in self.lingering}
        for info in self.strays.adopted(self.by_pid, guard.pid):
            if info.pgrp not in self._adopted_groups and info.pgrp not in watched:
                self._adopted_groups.add(info.pgrp)
                guard.watch(info.pgrp, STRAY_GRACE)
                guard.flush()  # before it is said: the guard knows it from then on
                name = comm(info.pid)
                self.records.emit(
                    Said(
                        "INFO",
                        "launch",
                        f"{name} [pid {info.pid}] left the process that started it and is now"
                        f" mlaunch's: its group {info.pgrp} ends with the run, even after"
                        " kill -9 of mlaunch",
                    )
                )
        self.timers.add(ADOPTED_POLL, self._watch_adopted, False, True)

    def _replaced(self, process: Process) -> bool:
        """Whether another instance of ``process``'s label takes its place (a respawn is
        scheduled, or the user's restart started it)."""
        if process.user_stop == "restart":
            return True
        return self.states[process.label].state == RESTARTING

    def _end_group(self, process: Process) -> None:
        """End what a dead instance left in its process group, with the instance: SIGTERM now,
        SIGKILL after ``STRAY_GRACE`` (each respawn used to leave them running until the run
        ended). Said once, naming the label and the group."""
        if not process.signal_group(signal.SIGTERM, wake=True):
            return
        self.records.emit(
            Said(
                "INFO",
                process.label,
                f"ending what the exited instance left in its process group {process.pid}"
                " (SIGTERM, SIGKILL after"
                f" {STRAY_GRACE:g} s): a new instance takes its place",
            )
        )

        def kill() -> None:
            if process.check_group():
                process.signal_group(signal.SIGKILL)
            elif process in self.lingering:  # a crash loop must not grow the list forever
                self.lingering.remove(process)
                if self.guard is not None:
                    self.guard.forget(process.pid)

        self.timers.add(STRAY_GRACE, kill, False, False)

    def _exited(self, process: Process) -> None:
        """Where a process's exit becomes a log line, handler calls, a shutdown, a respawn.

        Called with the stream held, so every subscriber sees ``Exited`` before what follows
        from it: the printer says it, the launch file's OnProcessExit and on_exit handlers
        fire (mlaunch.engine.handlers), lifecycle driving and smoke checks take note. A required
        process decides the run first, so the shutdown names it (its on_exit=Shutdown() then
        has nothing to do). Then the respawn policy (mlaunch.engine.respawn) decides.
        """
        spec = process.spec
        code = process.returncode if process.returncode is not None else 0
        self.records.emit(Exited(process, code))
        if spec.required and not process.stopping:
            # A required process decides the run: it ends it, and its failure is the run's.
            if code != 0:
                self.exit_status(EXIT_FAILURE)
            self.begin_shutdown(f"required process {spec.label} {describe_status(code)}")
        self.respawns.after_exit(process, code, shutting_down=self.shutting_down)
        if self.states[spec.label].state != RESTARTING:
            self.executor.ended_for_good(spec)

    def cancel_respawn(self, label: str, outcome: str) -> None:
        """The respawn ``label`` waits for does not happen (runtime control's stop)."""
        self.respawns.cancel(label, outcome)

    def start_again(self, old: Process) -> object:
        """Start ``old``'s spec again now, as the user asked (``Respawns.start_again``)."""
        return self.respawns.start_again(old)

    def _forget(self, old: Process) -> None:
        if not old.streams and old not in self.lingering and old in self.processes:
            self.processes.remove(old)  # a crash loop must not grow the list forever
