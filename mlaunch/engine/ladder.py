"""The stop ladder: how one process group is stopped, step by step, each step a record.

SIGINT first (with SIGCONT, so a stopped process wakes up to die), SIGTERM after the process's
``sigterm_timeout``, SIGKILL after its ``sigkill_timeout``; each escalation is an Escalated record
on the record stream (the printer says it). The whole process group is signalled, as every child
runs in its own session.
"""

from __future__ import annotations

import signal
from collections.abc import Callable

from mlaunch.engine.process import Process
from mlaunch.engine.process_state import STOPPING, ProcessState
from mlaunch.plan.records import Escalated, Record


class StopLadder:
    """Stops process groups for one run; ``schedule(delay, callback)`` is the loop's timer."""

    def __init__(
        self,
        schedule: Callable[[float, Callable[[], None]], object],
        emit: Callable[[Record], None],
        states: dict[str, ProcessState],
    ) -> None:
        self.schedule = schedule
        self.emit = emit
        self.states = states

    def stop(self, process: Process, *, sigint: bool = True) -> None:
        """SIGINT now (unless not ``sigint``), then SIGTERM and SIGKILL while the group lives on."""
        if process.stopping:
            return
        process.stopping = True
        if process.running:
            self.states[process.label].state = STOPPING
        spec = process.spec
        if sigint:
            if not process.signal_group(signal.SIGINT, wake=True):
                return
        elif not (process.running or process.check_group()):
            return

        def escalate(sig: int, waited: float, next_step: Callable[[], None] | None) -> None:
            if not (process.running or process.check_group()):
                return
            previous = process.signals_sent[-1] if process.signals_sent else 0
            process.signal_group(sig, wake=True)
            self.emit(Escalated(process, sig, previous, waited))
            if next_step is not None:
                next_step()

        def to_kill() -> None:
            self.schedule(
                spec.sigkill_timeout,
                lambda: escalate(signal.SIGKILL, spec.sigkill_timeout, None),
            )

        self.schedule(
            spec.sigterm_timeout, lambda: escalate(signal.SIGTERM, spec.sigterm_timeout, to_kill)
        )

    def kill(self, processes: list[Process]) -> None:
        """SIGKILL to every group still alive, at once (a second Ctrl-C)."""
        for process in processes:
            if process.running or process.check_group():
                process.stopping = True
                process.signal_group(signal.SIGKILL)
