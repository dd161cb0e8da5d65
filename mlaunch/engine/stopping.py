"""How a Supervisor stops: the two-phase shutdown, holding a process back, the second Ctrl-C.

A base of mlaunch.engine.supervisor.Supervisor, apart so that module stays readable; the state it
works on (processes, records, the stop ladder, the event stream ...) is the supervisor's own,
declared here for the type checker only.
"""

from __future__ import annotations

import signal

from mlaunch.engine.process import signal_name
from mlaunch.engine.records import RESTARTING
from mlaunch.plan.errors import exit_for_signal
from mlaunch.plan.events import Interrupted, ShutdownBegun, StoppingAll

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.engine import guard as guards
    from mlaunch.engine.ladder import StopLadder
    from mlaunch.engine.process import Process
    from mlaunch.engine.records import ProcessRecord
    from mlaunch.engine.signals import SignalWatch
    from mlaunch.engine.strays import Strays
    from mlaunch.engine.timers import Timers
    from mlaunch.plan.events import EventStream


class Stopping:
    """Shutdown and signal handling of a Supervisor (which sets every attribute below)."""

    processes: list[Process]
    lingering: list[Process]
    by_pid: dict[int, Process]
    records: dict[str, ProcessRecord]
    timers: Timers
    signals: SignalWatch
    strays: Strays
    guard: guards.Guard | None
    events: EventStream
    ladder: StopLadder
    shutting_down: bool
    shutdown_reason: str
    exit_code: int
    _held: set[Process]
    _stop_presses: int
    _kill_now: bool

    if TYPE_CHECKING:  # the supervisor's own, used by the emergency stop

        def _reap(self) -> None: ...

    # --- stopping ----------------------------------------------------------------------------

    def begin_shutdown(self, reason: str, *, due_to_signal: int | None = None) -> None:
        """Shut the launch down, in two phases on the stream.

        ShutdownBegun: the printer says why, OnShutdown handlers run (and may ``hold_stop``
        a process); then StoppingAll: every process not held gets its stop ladder.
        """
        if self.shutting_down:
            return
        self.shutting_down = True
        self.shutdown_reason = reason
        self.timers.shutting_down()  # pending respawns and TimerActions included
        for record in self.records.values():
            if record.state == RESTARTING:
                record.not_restarting()
        self.events.emit(ShutdownBegun(reason, due_to_signal))
        self.events.emit(StoppingAll())

    def _stop_all(self) -> None:
        for process in self.processes:
            if process.running and process not in self._held:
                self.stop(process)
        for process in self.lingering:
            if process.check_group() and not process.stopping:
                self.stop(process)

    def hold_stop(self, process: Process) -> None:
        """Keep ``process`` out of the stop ladder until ``release_stop`` (or a second Ctrl-C).

        For work that must happen while a process still runs at shutdown, such as deactivating
        a lifecycle node before it is signalled. Call it on ShutdownBegun: the ladder starts
        for every process not held at the StoppingAll that follows it.
        """
        self._held.add(process)

    def release_stop(self, process: Process) -> None:
        """Hand a held process to the stop ladder (now, if the launch is shutting down)."""
        self._held.discard(process)
        if self.shutting_down and process.running:
            self.stop(process)

    def stop(self, process: Process) -> None:
        """The stop ladder for one process group (mlaunch.engine.ladder)."""
        self.ladder.stop(process)

    def kill_everything(self) -> None:
        """A second Ctrl-C: SIGKILL every group and every stray at once."""
        self._kill_now = True
        self.ladder.kill(self.processes + self.lingering)
        self.events.emit(StoppingAll(kill=True))
        self.begin_shutdown("killed")

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

    # --- signals -----------------------------------------------------------------------------

    def _handle_signals(self) -> None:
        pending = self.signals.pending
        while pending:
            sig = pending.pop(0)
            if sig == signal.SIGCHLD:
                self._reap()
                continue
            self._stop_pressed(sig)
        self._reap()

    def _handle_stop_signals(self) -> None:
        """Act on the stop signals recorded so far; leave exits (SIGCHLD) for the loop."""
        pending = self.signals.pending
        i = 0
        while i < len(pending):  # in place: the handler may append meanwhile
            sig = pending[i]
            if sig == signal.SIGCHLD:
                i += 1
                continue
            del pending[i]
            self._stop_pressed(sig)

    def _stop_pressed(self, sig: int) -> None:
        self._stop_presses += 1
        if self._stop_presses == 1:
            self.exit_code = max(self.exit_code, exit_for_signal(sig))
            self.events.emit(Interrupted(sig))
            self.begin_shutdown(f"{signal_name(sig)} received", due_to_signal=sig)
        else:
            self.kill_everything()
