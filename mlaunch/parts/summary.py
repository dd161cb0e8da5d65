"""The exit summary: a table of every process at the end of a run.

Each process's last pid, how it ended, restarts, total run time, peak memory and CPU time. It is
printed when the run had more than one process or anything failed (with ``--quiet``: only when
something failed), so a one-process run that ends cleanly stays quiet. Peak memory and CPU time
come from the kernel (wait4's rusage of each exit), exact and free: nothing is sampled and
nothing is imported for it. The durations and sizes are written as the ``--status`` view
(mlaunch.parts.status) writes them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping

from mlaunch.engine.process_state import GAVE_UP, ProcessState
from mlaunch.plan.records import Record, Summary


def format_duration(seconds: float) -> str:
    """``0.42 s``, ``4.20 s``, ``42.0 s``, ``12:03``, ``1:02:03``."""
    if seconds < 10:
        return f"{seconds:.2f} s"
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, secs = divmod(int(seconds), 60)
    if minutes < 60:
        return f"{minutes}:{secs:02d}"
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}"


def format_bytes(size: float) -> str:
    """``812 KiB``, ``35.2 MiB``, ``1.3 GiB``."""
    if size <= 0:
        return "-"
    if size < 1 << 20:
        return f"{size / 1024:.0f} KiB"
    if size < 1 << 30:
        return f"{size / (1 << 20):.1f} MiB"
    return f"{size / (1 << 30):.1f} GiB"


def summary_wanted(states: Iterable[ProcessState], *, quiet: bool = False) -> bool:
    """More than one process, or any failure (only a failure with ``quiet``)."""
    states = list(states)
    failed = any(r.failed or r.state == GAVE_UP for r in states)
    return failed if quiet else (len(states) > 1 or failed)


def render_summary(states: Iterable[ProcessState]) -> str:
    """The summary table as plain text (it goes to the screen and into launch.log)."""
    head = ("process", "pid", "result", "restarts", "run time", "peak memory", "cpu time")
    rows = [
        (
            r.label,
            str(r.pid or "-"),
            r.outcome or r.state,
            str(r.restarts),
            format_duration(r.run_time),
            format_bytes(r.peak_rss),
            f"{r.cpu_time:.2f} s",
        )
        for r in states
    ]
    widths = [max(len(row[i]) for row in [head, *rows]) for i in range(len(head))]
    right = {1, 3, 4, 5, 6}

    def line(cells: tuple[str, ...]) -> str:
        parts = [
            c.rjust(w) if i in right else c.ljust(w)
            for i, (c, w) in enumerate(zip(cells, widths, strict=True))
        ]
        return "  " + "  ".join(parts).rstrip()

    failed = sum(1 for r in states if r.failed or r.state == GAVE_UP)
    title = f"Summary: {len(rows)} process{'es' if len(rows) != 1 else ''}"
    if failed:
        title += f", {failed} failed"
    return "\n".join([title, line(head), *(line(row) for row in rows)]) + "\n"


class ExitSummary:
    """The summary of a run's processes, said when the run ends (``close``): ``states`` is the
    run's read-only view of them, ``emit`` its record stream's (the printer says the table)."""

    def __init__(
        self,
        states: Mapping[str, ProcessState],
        emit: Callable[[Record], None],
        *,
        quiet: bool = False,
    ) -> None:
        self.states = states
        self.emit = emit
        self.quiet = quiet

    def close(self) -> None:
        states = list(self.states.values())
        if states and summary_wanted(states, quiet=self.quiet):
            self.emit(Summary(render_summary(states)))
