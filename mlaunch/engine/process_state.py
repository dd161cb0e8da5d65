"""What the run knows about each process label over its whole life: for the status view and summary.

A ProcessState survives respawns (one per label): its state, last pid, restarts, total run time,
peak memory and CPU time (from wait4's rusage, so nothing is sampled), and how it ended.
"""

from __future__ import annotations

from mlaunch.engine.process import Process, describe_status, signal_name
from mlaunch.plan.steps import ProcessSpec

# ProcessState.state values.
RUNNING = "running"
STOPPING = "stopping"
RESTARTING = "restarting"
FINISHED = "finished"
FAILED = "failed"
GAVE_UP = "gave up"
STOPPED = "stopped"  # by the user (mlaunch.parts.control): it stays down until started again
USER_STOPPED = "stopped by the user"


class ProcessState:
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
        "user_starts",
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
        user_starts: int = 0,
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
        # Of ``restarts``, those the user asked for: they do not use up respawn's max_retries.
        self.user_starts = user_starts

    def __repr__(self) -> str:
        return (
            f"ProcessState(label={self.label!r}, state={self.state!r}, pid={self.pid},"
            f" restarts={self.restarts}, outcome={self.outcome!r})"
        )

    def failed_to_start(self, reason: str) -> None:
        self.state, self.failed, self.returncode = FAILED, True, 127
        self.outcome = f"failed to start: {reason}"

    def ended(self, process: Process) -> None:
        """Add up a reaped instance of this label: its status, run time, memory, CPU, signals."""
        code = process.returncode if process.returncode is not None else 0
        self.returncode = code
        self.run_time += max(0.0, process.ended_at - process.started_at)
        self.peak_rss = max(self.peak_rss, process.peak_rss)
        self.cpu_time += process.cpu_time
        self.signals.extend(process.signals_sent)
        self.failed = False
        if process.user_stop:
            self.outcome = USER_STOPPED
            self.state = RESTARTING if process.user_stop == "restart" else STOPPED
            return
        if process.stopping:
            self.outcome = _stopped_outcome(process, code)
        elif code == 0:
            self.outcome = "finished cleanly"
        else:
            self.failed = True
            self.outcome = describe_status(code) + (" (core dumped)" if process.core_dumped else "")
        self.state = FAILED if self.failed else FINISHED

    def not_restarting(self) -> None:
        """A pending restart was cancelled (the launch shuts down): it ended as it last did."""
        if self.outcome == USER_STOPPED:
            self.state, self.restart_at = STOPPED, None
            return
        self.state, self.restart_at = (FAILED if self.failed else FINISHED), None


def _stopped_outcome(process: Process, code: int) -> str:
    if code < 0 and -code in process.signals_sent:
        return f"stopped by {signal_name(-code)}"
    if code == 0:
        return "stopped, exited cleanly"
    return f"stopped, {describe_status(code)}"
