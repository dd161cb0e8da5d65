"""What each running process costs now: CPU, memory, threads and open files of its group.

A launched process is counted with the living members of its process group (a shell's or a
wrapper's children are part of what that label costs), as the ``--status`` view shows it and
``--metrics`` writes it. psutil reads /proc; it is imported on the first sample. A ``Sample`` is
every process at one moment, what ``--metrics`` and the launch panel are handed.
"""

from __future__ import annotations

from typing import Any

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from mlaunch.parts.control import ProcessInfo


class Usage:
    """One process group's cost now: ``cpu`` percent of one core since the last sample,
    ``rss`` bytes, ``threads`` and ``files`` (open file descriptors) summed over its members."""

    __slots__ = ("cpu", "files", "rss", "threads")

    def __init__(self, cpu: float = 0.0, rss: int = 0, threads: int = 0, files: int = 0) -> None:
        self.cpu = cpu
        self.rss = rss
        self.threads = threads
        self.files = files


def group_members(pgids: set[int]) -> dict[int, list[int]]:
    """Living members of each of the process groups ``pgids`` (one /proc scan for all)."""
    from mlaunch.engine.proctable import scan

    groups: dict[int, list[int]] = {pgid: [] for pgid in pgids}
    for proc in scan():
        if proc.pgrp in groups and not proc.zombie:
            groups[proc.pgrp].append(proc.pid)
    return groups


class GroupSampler:
    """Samples process groups again and again: CPU percent is measured between two calls.

    ``details`` False reads only CPU and memory (what the status view shows, at half the cost).
    """

    def __init__(self, details: bool = True) -> None:
        self.details = details
        self._procs: dict[int, Any] = {}  # pid: psutil.Process, kept between samples

    def sample(self, groups: dict[int, list[int]]) -> dict[int, Usage]:
        """{pgid: Usage} for ``groups`` ({pgid: member pids}); members gone are skipped."""
        import psutil

        usage: dict[int, Usage] = {}
        alive: dict[int, Any] = {}
        for pgid, pids in groups.items():
            total = Usage()
            for pid in pids:
                proc = self._procs.get(pid)
                try:
                    if proc is None:
                        proc = psutil.Process(pid)
                        proc.cpu_percent(None)  # the first call only starts the measurement
                    with proc.oneshot():
                        total.cpu += proc.cpu_percent(None)
                        total.rss += proc.memory_info().rss
                        if self.details:
                            total.threads += proc.num_threads()
                            total.files += proc.num_fds()
                except psutil.Error:
                    continue
                alive[pid] = proc
            usage[pgid] = total
        self._procs = alive
        return usage


class Sample:
    """Every process at one moment: ``rows`` of (ProcessInfo, Usage or None when not running);
    ``extra`` what the ``readers`` said on the loop thread at that moment (by name)."""

    __slots__ = ("elapsed", "extra", "rows", "time")

    def __init__(
        self,
        time: float,
        elapsed: float,
        rows: list[tuple[ProcessInfo, Usage | None]],
        extra: dict[str, object] | None = None,
    ) -> None:
        self.time = time
        self.elapsed = elapsed
        self.rows = rows
        self.extra = {} if extra is None else extra
