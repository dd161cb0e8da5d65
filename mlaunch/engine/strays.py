"""Stray processes: descendants of the run that left every process group the supervisor watches.

mlaunch becomes the children's subreaper, so a grandchild that escapes into a session of its own
is re-parented to mlaunch, not to init. Every child's environment carries the run's marker
(``MLAUNCH_RUN_ID``, inherited by grandchildren), so a process of the run is found in /proc even
if it escaped before the subreaper was set.

At shutdown the sweep walks mlaunch's process tree (/proc/<pid>/task/*/children, a few reads);
the full /proc scan for the marker (every process's environment) is only made when the walk
cannot be trusted to see everything: without the subreaper, or when a child had already exited
before the subreaper was set (its orphans went to init).
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Callable, Iterable

from mlaunch.engine import proctable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.engine.cgroup import RunCgroup

# How long an escaped descendant gets between SIGTERM and SIGKILL at shutdown.
STRAY_GRACE = 2.0
PR_SET_CHILD_SUBREAPER = 36


def set_subreaper(on: bool) -> bool:
    """Make this process the subreaper of its descendants (or not): an orphan among them is
    re-parented to it, not to init. Whether the kernel took it."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return bool(libc.prctl(PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0) == 0)
    except (OSError, AttributeError):
        return False


class Strays:
    """Finds and ends one run's stray processes (SIGTERM, then SIGKILL after ``grace``).

    ``adopt``: become the subreaper and end every descendant; an embedder with children of its
    own passes False (the run's processes are still found by their marker). ``cgroup``: the
    run's cgroup (mlaunch.engine.cgroup), whose members are the run's whatever their environment.
    """

    def __init__(
        self,
        run_id: str,
        *,
        adopt: bool = True,
        grace: float = STRAY_GRACE,
        clock: Callable[[], float] = time.monotonic,
        cgroup: RunCgroup | None = None,
    ) -> None:
        self.run_id = run_id
        self.cgroup = cgroup
        self.adopt = adopt
        self.grace = grace
        self.clock = clock
        self.subreaper = False
        # A child had exited before the subreaper was set: its orphans may have gone to init,
        # where only the marker scan finds them.
        self.escaped = False
        self.seen: dict[int, float] = {}
        self._signalled: set[tuple[int, int]] = set()

    def adopt_orphans(self) -> None:
        """Become the subreaper (after the first spawns: ctypes costs milliseconds)."""
        if self.adopt:
            self.set_subreaper(True)
            self.escaped = self.a_child_has_exited()

    def release(self) -> None:
        if self.subreaper:
            self.set_subreaper(False)

    def set_subreaper(self, on: bool) -> None:
        """As subreaper, orphaned descendants are re-parented to mlaunch, not to init."""
        self.subreaper = set_subreaper(on) and on

    def a_child_has_exited(self) -> bool:
        """Whether a child is already a zombie (exited before we became subreaper)."""
        try:
            info = os.waitid(os.P_ALL, 0, os.WEXITED | os.WNOHANG | os.WNOWAIT)
        except (ChildProcessError, OSError):
            return False
        return info is not None

    def sweep(
        self, ours: Iterable[int], skip: int | None, *, now_kill: bool
    ) -> tuple[bool, list[tuple[str, int, int]]]:
        """Signal the strays not yet signalled: whether any lives, and what was sent this time.

        Each signal sent is ``(name, pid, signal)``. SIGTERM and SIGCONT first, SIGKILL after
        ``grace`` (at once with ``now_kill``: a second Ctrl-C).
        """
        sent: list[tuple[str, int, int]] = []
        now = self.clock()
        strays = self.find(ours, skip)
        for proc in strays:
            first = self.seen.setdefault(proc.pid, now)
            late = now_kill or now - first >= self.grace
            sig = signal.SIGKILL if late else signal.SIGTERM
            if (proc.pid, sig) in self._signalled:
                continue
            self._signalled.add((proc.pid, sig))
            name = comm(proc.pid)
            try:
                os.kill(proc.pid, sig)
                if sig == signal.SIGTERM:
                    os.kill(proc.pid, signal.SIGCONT)
            except OSError:
                continue
            sent.append((name, proc.pid, sig))
        return bool(strays), sent

    def find(
        self, ours: Iterable[int], skip: int | None, *, thorough: bool = False
    ) -> list[proctable.ProcInfo]:
        """Processes of the run outside our own children (``ours``): descendants, and marked ones.

        The walk down our process tree is cheap and, as subreaper, sees every descendant that
        was orphaned after the subreaper was set. The marker scan reads every process's
        environment (~ms), so it is made only when something may have escaped the walk.
        ``skip``: the guard's pid.
        """
        found: dict[int, proctable.ProcInfo] = {}
        if self.subreaper or self.adopt:
            found.update((p.pid, p) for p in proctable.tree(os.getpid()))
        if thorough or not self.subreaper or self.escaped:
            found.update((p.pid, p) for p in proctable.marked(self.run_id))
        if self.cgroup is not None:
            # Whatever it did (a daemon that cleared its environment and left before we
            # were subreaper), a process of the run is in its cgroup.
            me = os.getpid()
            for pid in self.cgroup.members():
                info = proctable.proc_info(pid) if pid != me and pid not in found else None
                if info is not None and not info.zombie:
                    found[pid] = info
        if skip is not None:
            found.pop(skip, None)
        for pid in ours:  # our own children are the ladder's business
            found.pop(pid, None)
        return list(found.values())

    def adopted(self, ours: Iterable[int], skip: int | None) -> list[proctable.ProcInfo]:
        """Orphans re-parented to mlaunch as subreaper (a daemon that double-forked): living
        direct children that are not ``ours``. A few reads (one per thread of mlaunch)."""
        if not self.subreaper or not proctable.children_files():
            return []
        me = os.getpid()
        known = set(ours)
        if skip is not None:
            known.add(skip)
        found = []
        try:
            tids = os.listdir(f"/proc/{me}/task")
        except OSError:
            return []
        for tid in tids:
            try:
                listed = proctable.read_file(f"/proc/{me}/task/{tid}/children").split()
            except OSError:
                continue
            for word in listed:
                pid = int(word)
                if pid in known:
                    continue
                known.add(pid)
                info = proctable.proc_info(pid)
                if info is not None and not info.zombie:
                    found.append(info)
        return found

    def kill_all(self, ours: Iterable[int], skip: int | None) -> None:
        """SIGKILL every stray at once, looking thoroughly (the loop itself failed)."""
        for proc in self.find(ours, skip, thorough=True):
            try:
                os.kill(proc.pid, signal.SIGKILL)
            except OSError:
                pass


def comm(pid: int) -> str:
    """The process's short name, or ``?`` once it is gone."""
    try:
        with open(f"/proc/{pid}/comm") as f:
            return f.read().strip()
    except OSError:
        return "?"
