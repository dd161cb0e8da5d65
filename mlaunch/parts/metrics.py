"""What each process of a run costs, once a second: for the dashboard and ``--metrics FILE.csv``.

A supervisor timer takes the list of processes (mlaunch.parts.control's, what ``mlaunch ctl
list`` shows) once a second, on the loop thread, and hands it to a thread of its own, which
reads /proc (mlaunch.parts.usage) and hands the sample to its listeners: the CSV file, the
dashboard. The loop never waits for /proc: when the thread is behind, that second is skipped.

The CSV has one row per running process per second::

    time,elapsed,label,pid,state,cpu_percent,rss_bytes,threads,open_files

``time`` is UNIX time, ``elapsed`` seconds since the first sample; CPU is percent of one core,
summed over the process's group, as are the other columns. At the end of the run a small HTML
report is written beside it (``FILE.html``): a table of what each process cost and its CPU and
memory over time (mlaunch.parts.metrics_report).
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable

from mlaunch.engine.part import Part
from mlaunch.parts.usage import GroupSampler, Sample, group_members
from mlaunch.plan.records import Said

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import IO

    from mlaunch.engine.part import AttachedRun
    from mlaunch.parts.control import Control, ProcessInfo

PERIOD = 1.0
COLUMNS = (
    "time",
    "elapsed",
    "label",
    "pid",
    "state",
    "cpu_percent",
    "rss_bytes",
    "threads",
    "open_files",
)


Listener = Callable[[Sample], None]


class Metrics(Part):
    """Samples the run's processes every ``period`` s and hands each Sample to ``listeners``
    (on its own thread); ``csv_path`` writes them, and the HTML report at close."""

    def __init__(
        self,
        supervisor: AttachedRun,
        control: Callable[[], Control],
        *,
        csv_path: str | None = None,
        period: float = PERIOD,
        wall_clock: Callable[[], float] = time.time,
    ) -> None:
        self.supervisor = supervisor
        self.control = control
        self.period = period
        self.wall_clock = wall_clock
        self.csv_path = csv_path
        self.listeners: list[Listener] = []
        # What else each sample carries, read on the loop thread (the run's readiness ...);
        # a reader that raises gives None.
        self.readers: dict[str, Callable[[], object]] = {}
        self.history: list[Sample] = []  # kept for the report when there is a CSV file
        self._csv: IO[str] | None = None
        self._start: float | None = None
        self._queue: queue.Queue[tuple[float, list[ProcessInfo], dict[str, object]] | None] = (
            queue.Queue(maxsize=1)
        )
        self._sampler = GroupSampler()
        self._closed = False
        self._failure = ""  # what the sampling thread could not do, said by the loop
        self._beat: float | None = None  # the loop's clock at the first sample
        if csv_path is not None:
            self._csv = _open_csv(csv_path)
        self._thread = threading.Thread(target=self._work, name="mlaunch-metrics", daemon=True)
        self._thread.start()
        supervisor.schedule(0.0, self._tick, keeps_alive=False)

    def _tick(self) -> None:
        """Loop thread: the processes now, to the sampling thread (skipped when it is behind)."""
        if self._closed:
            return
        if self._failure:
            self.supervisor.records.emit(Said("WARNING", "launch", self._failure))
            self._failure = ""
        if not self._queue.full():
            item = (self.wall_clock(), self.control().processes(), self._read())
            try:
                self._queue.put_nowait(item)
            except queue.Full:
                pass
        # On the run's own beat (start + k periods), so a late turn of the loop does not drift.
        now = self.supervisor.clock()
        if self._beat is None:
            self._beat = now
        late = (now - self._beat) % self.period
        self.supervisor.schedule(self.period - late, self._tick, keeps_alive=False)

    def _read(self) -> dict[str, object]:
        extra: dict[str, object] = {}
        for name, reader in self.readers.items():
            try:
                extra[name] = reader()
            except Exception as e:  # what the panel shows, never a reason to stop sampling
                extra[name] = None
                self._failure = f"metrics: {name} could not be read: {type(e).__name__}: {e}"
        return extra

    def _work(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            try:
                self._take(*item)
            except Exception as e:  # said by the loop's next tick; the next sample is tried
                self._failure = f"metrics: a sample failed: {type(e).__name__}: {e}"

    def _take(self, now: float, infos: list[ProcessInfo], extra: dict[str, object]) -> None:
        if self._start is None:
            self._start = now
        running = {info.pid for info in infos if info.pid}
        usage = self._sampler.sample(group_members(running))
        rows = [(info, usage.get(info.pid) if info.pid else None) for info in infos]
        sample = Sample(now, now - self._start, rows, extra)
        if self._csv is not None:
            self.history.append(sample)
            _write_rows(self._csv, sample)
        for listener in list(self.listeners):
            listener(sample)

    def close(self) -> None:
        """Stop sampling; close the CSV file and write the HTML report beside it."""
        if self._closed:
            return
        self._closed = True
        try:
            while True:
                self._queue.get_nowait()
        except queue.Empty:
            pass
        self._queue.put(None)
        self._thread.join(timeout=5.0)
        if self._csv is None or self.csv_path is None:
            return
        self._csv.close()
        from mlaunch.parts.metrics_report import report_path, write_report

        path = report_path(self.csv_path)
        try:
            write_report(path, self.history)
        except OSError as e:
            text = f"metrics: cannot write the report {path}: {e.strerror or e}"
            self.supervisor.records.emit(Said("WARNING", "launch", text))
            return
        text = f"metrics: {self.csv_path}, report {path}"
        self.supervisor.records.emit(Said("INFO", "launch", text))


def _open_csv(path: str) -> IO[str]:
    f = open(path, "w", encoding="utf-8", newline="")  # noqa: SIM115 (closed by Metrics.close)
    f.write(",".join(COLUMNS) + "\n")
    f.flush()
    return f


def _write_rows(f: IO[str], sample: Sample) -> None:
    lines = []
    for info, usage in sample.rows:
        if usage is None:
            continue
        label = info.label.replace('"', '""')
        lines.append(
            f'{sample.time:.3f},{sample.elapsed:.3f},"{label}",{info.pid},{info.state},'
            f"{usage.cpu:.1f},{usage.rss},{usage.threads},{usage.files}\n"
        )
    f.write("".join(lines))
    f.flush()
