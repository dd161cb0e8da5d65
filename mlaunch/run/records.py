"""What the run knows about each process label over its whole life: for the status view and summary.

A ProcessRecord survives respawns (one per label): its state, last pid, restarts, total run time,
peak memory and CPU time (from wait4's rusage, so nothing is sampled), and how it ended.
"""

from __future__ import annotations

from mlaunch.run.plan import ProcessSpec

# ProcessRecord.state values.
RUNNING = "running"
STOPPING = "stopping"
RESTARTING = "restarting"
FINISHED = "finished"
FAILED = "failed"
GAVE_UP = "gave up"


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
