"""How a run stops: the two-phase shutdown, holding a process back, the second Ctrl-C.

``Stopping`` is one object of the Supervisor (mlaunch.engine.supervisor) with state of its own:
whether the run is shutting down and why, the processes held back from the stop ladder, the
stop presses. What it acts on (the run's processes, their states, the stop ladder, the record
stream, the timers) is handed to it when it is made.
"""

from __future__ import annotations

import signal

from mlaunch.engine.process import signal_name
from mlaunch.engine.process_state import RESTARTING
from mlaunch.plan.errors import exit_for_signal
from mlaunch.plan.records import Interrupted, ShutdownBegun, ShutdownRepeated, StoppingAll

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from mlaunch.engine.ladder import StopLadder
    from mlaunch.engine.process import Process
    from mlaunch.engine.process_state import ProcessState
    from mlaunch.engine.timers import Timers
    from mlaunch.plan.records import RecordStream


class Stopping:
    """The shutdown of one run.

    ``processes`` and ``lingering`` are the supervisor's lists (kept up to date by it);
    ``exit_status(code)`` raises the run's exit status to at least ``code``.
    """

    def __init__(
        self,
        *,
        records: RecordStream,
        timers: Timers,
        states: Mapping[str, ProcessState],
        ladder: StopLadder,
        processes: list[Process],
        lingering: list[Process],
        exit_status: Callable[[int], None],
    ) -> None:
        self.records = records
        self.timers = timers
        self.states = states
        self.ladder = ladder
        self.processes = processes
        self.lingering = lingering
        self.exit_status = exit_status
        self.active = False
        self.reason = ""
        # After a second Ctrl-C: strays too are killed without their grace.
        self.kill_now = False
        self._held: set[Process] = set()
        self._presses = 0
        # Whether the stop ladders of this shutdown start with SIGINT (RequestShutdown says).
        self.send_sigint = True

    def begin(
        self, reason: str, *, due_to_signal: int | None = None, send_sigint: bool = True
    ) -> None:
        """Shut the launch down, in two phases on the stream.

        ShutdownBegun: the printer says why, OnShutdown handlers run (and may ``hold`` a
        process); then StoppingAll: every process not held gets its stop ladder (``stop_all``,
        the supervisor's reaction), from SIGTERM after its timeout when not ``send_sigint``.
        """
        if self.active:
            return
        self.active = True
        self.reason = reason
        self.send_sigint = send_sigint
        self.timers.shutting_down()  # pending respawns and TimerActions included
        for record in self.states.values():
            if record.state == RESTARTING:
                record.not_restarting()
        self.records.emit(ShutdownBegun(reason, due_to_signal))
        self.records.emit(StoppingAll())

    def request(
        self, reason: str, *, due_to_signal: int | None = None, send_sigint: bool = True
    ) -> None:
        """A Shutdown of the launch file (action or event): it begins the shutdown or, while
        one is under way, goes to the OnShutdown handlers alone (ShutdownRepeated)."""
        if self.active:
            self.records.emit(ShutdownRepeated(reason, due_to_signal))
        else:
            self.begin(reason, due_to_signal=due_to_signal, send_sigint=send_sigint)

    def stop_all(self) -> None:
        """The stop ladder for every process not held, and for groups left by their leader."""
        for process in self.processes:
            if process.running and process not in self._held:
                self.ladder.stop(process, sigint=self.send_sigint)
        for process in self.lingering:
            if process.check_group() and not process.stopping:
                self.ladder.stop(process, sigint=self.send_sigint)

    def hold(self, process: Process) -> None:
        """Keep ``process`` out of the stop ladder until ``release`` (or a second Ctrl-C).

        For work that must happen while a process still runs at shutdown, such as deactivating
        a lifecycle node before it is signalled. Call it on ShutdownBegun: the ladder starts
        for every process not held at the StoppingAll that follows it.
        """
        self._held.add(process)

    def release(self, process: Process) -> None:
        """Hand a held process to the stop ladder (now, if the launch is shutting down)."""
        self._held.discard(process)
        if self.active and process.running:
            self.ladder.stop(process, sigint=self.send_sigint)

    def kill_everything(self) -> None:
        """A second Ctrl-C: SIGKILL every group and every stray at once."""
        self.kill_now = True
        self.ladder.kill(self.processes + self.lingering)
        self.records.emit(StoppingAll(kill=True))
        self.begin("killed")

    def pressed(self, sig: int) -> None:
        """A stop signal (Ctrl-C, SIGTERM, SIGHUP): the first shuts down, the next kills."""
        self._presses += 1
        if self._presses == 1:
            self.exit_status(exit_for_signal(sig))
            self.records.emit(Interrupted(sig))
            self.begin(f"{signal_name(sig)} received", due_to_signal=sig)
        else:
            self.kill_everything()


def handle_signals(
    pending: list[int], reap: Callable[[], None], pressed: Callable[[int], None]
) -> None:
    """Act on the signals recorded so far: exits (SIGCHLD) are reaped, the others pressed."""
    while pending:
        sig = pending.pop(0)
        if sig == signal.SIGCHLD:
            reap()
            continue
        pressed(sig)
    reap()


def handle_stop_signals(pending: list[int], pressed: Callable[[int], None]) -> None:
    """Act on the stop signals recorded so far; leave exits (SIGCHLD) for the loop."""
    i = 0
    while i < len(pending):  # in place: the handler may append meanwhile
        sig = pending[i]
        if sig == signal.SIGCHLD:
            i += 1
            continue
        del pending[i]
        pressed(sig)
