"""The guard: ends a run's processes when mlaunch itself dies without stopping them (SIGKILL, OOM).

A supervisor can only stop its children while it lives. If mlaunch is killed with SIGKILL, its
children (each in a session of its own, so no terminal signal reaches them) would run on forever.
So at start mlaunch forks a tiny guard that holds the read end of a pipe. mlaunch tells it, one
short line per event, which process groups it started (``+pgid grace``) and which are gone
(``-pgid``), and says goodbye (``x``) once it has ended everything itself. If the pipe reaches
EOF without the goodbye, mlaunch is dead: the guard sends SIGTERM (and SIGCONT, for stopped
processes) to every group it was told about and to every process whose environment carries the
run's marker (``MLAUNCH_RUN_ID=<id>``, set in every child's environment and inherited by
grandchildren, so even one that started its own session is found), waits the groups' grace,
SIGKILLs what is left, removes mlaunch's private temp dir and the run's control socket
(``u<path>``, so ``mlaunch ctl`` finds no socket rather than a stale one) and says what it did
on stderr. When ``--status`` keys have the terminal in cbreak mode, mlaunch also sends the
settings to put back (``t ...``, mlaunch.engine.keyboard), and the guard puts them back first: the
shell gets its echo.

Why a forked process and not PR_SET_PDEATHSIG: that needs a preexec_fn in every spawn (slow,
and unsafe with threads) and never reaches grandchildren. A fork costs about a millisecond and
runs code already loaded; it never execs, imports nothing new until it has to clean up, and
leaves with ``os._exit`` so it never flushes mlaunch's buffers a second time.

mlaunch batches its lines: ``watch``/``forget`` only queue them, and the supervisor's loop calls
``flush`` once per turn, before it blocks (a write wakes the guard, ~0.2 ms each; one per spawn
was ~25 ms per hundred children). If mlaunch dies between a spawn and the flush, the marker
scan still finds that child.

At start the guard also removes the params folders of earlier runs that were killed together
with their guard (mlaunch.engine.privatedir.sweep_dead_runs), off mlaunch's path to its first child.

The /proc readers it shares with the supervisor's stray sweep live in mlaunch.engine.proctable.
"""

from __future__ import annotations

import os
import select
import signal
import time
from collections.abc import Iterable

from mlaunch.engine.privatedir import sweep_dead_runs
from mlaunch.engine.proctable import ProcInfo, marked, read_file, scan

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.engine.cgroup import RunCgroup

# How long the guard waits between SIGTERM and SIGKILL when it was told no grace.
DEFAULT_GRACE = 5.0
# An upper bound on that wait, whatever the launch file says: nobody is watching any more.
MAX_GRACE = 30.0
POLL = 0.02


def new_run_id() -> str:
    """A marker value unique to this run (pid plus random bits, so pid reuse cannot collide)."""
    return f"{os.getpid()}-{os.urandom(4).hex()}"


# --- the mlaunch side -----------------------------------------------------------------------------


class Guard:
    """mlaunch's end of the pipe to the guard process. Every method is cheap and never blocks.

    ``watch`` and ``forget`` queue their line; ``flush`` sends what is queued in one write.
    """

    # Queued lines the guard does not take (it stopped reading) are given up beyond this.
    MAX_PENDING = 1 << 20

    def __init__(self, pid: int, fd: int) -> None:
        self.pid = pid
        self.fd = fd
        self.broken = False
        self.writes = 0  # os.write calls made (what batching saves)
        self._pending: list[bytes] = []
        self._closed = False

    @classmethod
    def start(cls, run_id: str, *, temp_dir: str | None = None, cgroup: str | None = None) -> Guard:
        """Fork the guard. Call before any child is spawned (so it sees every group).

        ``cgroup``: the run's cgroup directory (mlaunch.engine.cgroup), whose members it ends too.
        """
        r, w = os.pipe()  # both ends close-on-exec: no child inherits them
        pid = os.fork()
        if pid == 0:
            code = 0
            try:
                os.close(w)
                _guard_main(r, run_id, temp_dir, cgroup)
            except BaseException:
                code = 1
            finally:
                os._exit(code)  # never return into mlaunch's (or pytest's) stack
        os.close(r)
        # A stopped or wedged guard must never stall the supervisor on a full pipe.
        os.set_blocking(w, False)
        return cls(pid, w)

    def watch(self, pgid: int, grace: float) -> None:
        """A process group mlaunch started; ``grace`` is its time between SIGTERM and SIGKILL."""
        if not self.broken:
            self._pending.append(b"+%d %.3f\n" % (pgid, grace))

    def forget(self, pgid: int) -> None:
        """The group is empty: its number may be reused by someone else's group."""
        if not self.broken:
            self._pending.append(b"-%d\n" % pgid)

    def terminal(self, line: bytes) -> None:
        """The settings to put back on the terminal (fd 0) should mlaunch die (``--status``
        keys change its mode; mlaunch.engine.keyboard makes the line), sent at once."""
        if not self.broken:
            self._pending.append(line)
            self.flush()

    def remove_on_death(self, path: str) -> None:
        """A file (the control socket) the guard removes, with its folder if that is then empty,
        should mlaunch die without saying goodbye."""
        if not self.broken and "\n" not in path:
            self._pending.append(b"u" + os.fsencode(path) + b"\n")

    @property
    def pending(self) -> bool:
        """Lines are queued for the next ``flush``."""
        return bool(self._pending)

    def flush(self) -> None:
        """Send the queued lines in one write; what the pipe does not take waits for the next."""
        if not self._pending or self.broken or self.fd < 0:
            return
        data = self._pending[0] if len(self._pending) == 1 else b"".join(self._pending)
        self._pending.clear()
        try:
            self.writes += 1
            n = os.write(self.fd, data)
        except BlockingIOError:
            n = 0  # the guard is behind (or stopped): keep the lines, unless far too many
        except OSError:
            self.broken = True  # the guard died: run on without it
            return
        if n < len(data):
            # The guard joins what it reads at newlines, so a line cut here is whole again.
            if len(data) - n > self.MAX_PENDING:
                self.broken = True
                return
            self._pending.append(data[n:])

    def dismiss(self) -> None:
        """Say goodbye now (the run has ended everything); ``close`` then only reaps the guard.

        The supervisor calls this when its loop ends, so the guard exits while mlaunch tidies
        up (summary, log files) instead of being waited for at the very end.
        """
        if self.fd < 0:
            return
        self._pending.append(b"x\n")
        self.flush()
        os.close(self.fd)
        self.fd = -1

    def close(self, *, clean: bool = True) -> None:
        """Say goodbye (nothing is left to end) and wait briefly for the guard to leave."""
        if self._closed:
            return
        self._closed = True
        if self.fd >= 0:
            if clean:
                self._pending.append(b"x\n")
                self.flush()
            os.close(self.fd)
            self.fd = -1
        _wait_exit(self.pid, 1.0 if clean else 0.0)


def _wait_exit(pid: int, timeout: float) -> None:
    """Reap ``pid`` once it exits, waiting up to ``timeout`` (a pidfd: no polling delay)."""
    try:
        if os.waitpid(pid, os.WNOHANG)[0]:
            return
    except ChildProcessError:
        return  # already reaped (by the supervisor's SIGCHLD handling)
    try:
        pidfd = os.pidfd_open(pid)
    except (AttributeError, OSError):
        pidfd = -1
    if pidfd >= 0:
        try:
            select.select([pidfd], [], [], timeout)
        finally:
            os.close(pidfd)
        try:
            os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            pass
        return
    deadline = time.monotonic() + timeout  # no pidfd (an old kernel): poll
    while time.monotonic() < deadline:
        try:
            if os.waitpid(pid, os.WNOHANG)[0]:
                return
        except ChildProcessError:
            return
        time.sleep(0.002)


# --- the guard process ---------------------------------------------------------------------------


def _guard_main(fd: int, run_id: str, temp_dir: str | None, cgroup: str | None) -> None:
    """The forked guard: read the pipe until EOF; without the goodbye, end the run."""
    parent = os.getppid()
    os.setsid()  # out of the terminal's process group: Ctrl-C and SIGHUP are mlaunch's to handle
    retitle(f"launch-guard [run {parent}]")
    signal.set_wakeup_fd(-1)
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGTSTP,
                signal.SIGTTIN, signal.SIGTTOU, signal.SIGPIPE):  # fmt: skip
        signal.signal(sig, signal.SIG_IGN)
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
    _keep_only_fds(fd)
    # Off mlaunch's path to its first child: the folders of runs killed with their guard.
    sweep_dead_runs()
    groups: dict[int, float] = {}
    leftovers: list[bytes] = []  # files to remove if mlaunch dies (its control socket)
    clean = False
    pending = b""
    terminal = b""  # the terminal settings mlaunch changed and would put back (a "t ..." line)
    while True:
        data = os.read(fd, 4096)
        if not data:
            break
        *lines, pending = (pending + data).split(b"\n")
        for line in lines:
            if line == b"x":
                clean = True
            elif line.startswith(b"+"):
                pgid, _, grace = line[1:].partition(b" ")
                groups[int(pgid)] = float(grace or DEFAULT_GRACE)
            elif line.startswith(b"-"):
                groups.pop(int(line[1:]), None)
            elif line.startswith(b"t"):
                terminal = line
            elif line.startswith(b"u"):
                leftovers.append(line[1:])
    if clean:
        return
    if terminal:
        _restore_terminal(terminal)  # first: a person is looking at that terminal
    for path in leftovers:
        _remove_file(path)
    ended = end_run(groups, run_id, cgroup, exclude={parent})
    removed = _remove_temp_dir(temp_dir)
    if ended or removed:
        what = f"ended {ended} of its processes" if ended else "no process was left"
        if removed:
            what += f" and removed {temp_dir}"
        if not cgroup:
            # Said where it matters: without the run's cgroup, a process that left its group
            # and cleared its environment (a daemon) cannot be told from anyone else's.
            what += " (found by process group and marker: the run had no cgroup of its own)"
        message = (
            f"[ERROR] [launch.guard]: mlaunch [pid {parent}] died without stopping its processes;"
            f" {what}\n"
        )
        try:
            os.write(2, message.encode("utf-8", "replace"))
        except OSError:
            pass


def _restore_terminal(line: bytes) -> None:
    """Put back the terminal settings mlaunch changed (its keys under ``--status``)."""
    import termios

    from mlaunch.engine.keyboard import parse_guard_line

    attrs = parse_guard_line(line)
    if attrs is None:
        return
    try:
        termios.tcsetattr(0, termios.TCSANOW, attrs)  # SIGTTOU is ignored here
    except (termios.error, OSError):
        pass


def _keep_only_fds(fd: int) -> None:
    """Hold nothing of mlaunch's open: no pipe of a child, no log file, not its stdout.

    A terminal on stdin stays: the guard puts its settings back if mlaunch dies in cbreak mode.
    """
    devnull = os.open(os.devnull, os.O_RDWR)
    if not os.isatty(0):
        os.dup2(devnull, 0)
    os.dup2(devnull, 1)
    os.close(devnull)
    os.closerange(3, fd)
    os.closerange(fd + 1, 1 << 16)


def end_run(
    groups: dict[int, float],
    run_id: str,
    cgroup: str | None = None,
    *,
    exclude: Iterable[int] = (),
) -> int:
    """SIGTERM (+SIGCONT) every living process of the run, SIGKILL what outlives its grace.

    A process in a watched group gets that group's grace (its sigkill_timeout); one found only
    by the marker or in the run's cgroup gets the longest. Returns how many processes were
    signalled. The cgroup is then killed whole (what forked meanwhile) and removed.
    ``exclude``: mlaunch itself, which may still be in its cgroup while the kernel ends it.
    """
    start = time.monotonic()
    longest = min(MAX_GRACE, max(groups.values(), default=DEFAULT_GRACE))
    first_seen: dict[int, float] = {}
    killed: set[int] = set()
    skip = set(exclude)
    run_cgroup = None
    if cgroup:
        from mlaunch.engine.cgroup import RunCgroup

        run_cgroup = RunCgroup(cgroup, os.path.dirname(cgroup))
    while time.monotonic() - start < longest + 5.0:
        living = [p for p in _living(groups, run_id, run_cgroup) if p.pid not in skip]
        if not living:
            break
        now = time.monotonic()
        for proc in living:
            if proc.pid not in first_seen:
                first_seen[proc.pid] = now
                _send(proc.pid, signal.SIGTERM)
                _send(proc.pid, signal.SIGCONT)  # a stopped process must wake up to die
            grace = min(MAX_GRACE, groups.get(proc.pgrp, longest))
            if now - first_seen[proc.pid] >= grace and proc.pid not in killed:
                killed.add(proc.pid)
                _send(proc.pid, signal.SIGKILL)
        time.sleep(POLL)
    if run_cgroup is not None:
        run_cgroup.remove()  # kills whatever is still in it first
    return len(first_seen)


def _living(groups: Iterable[int], run_id: str, cgroup: RunCgroup | None) -> list[ProcInfo]:
    """Living processes in the watched groups, carrying the run's marker, or in its cgroup."""
    procs = scan()
    wanted = set(groups)
    me = os.getpid()
    living = {p.pid: p for p in procs if p.pgrp in wanted and not p.zombie and p.pid != me}
    living.update((p.pid, p) for p in marked(run_id, procs))
    if cgroup is not None:
        members = set(cgroup.members())
        living.update((p.pid, p) for p in procs if p.pid in members and not p.zombie)
    return list(living.values())


def retitle(title: str) -> None:
    """Show ``title`` as this process's command line and name (ps, top, pkill, pkill -f).

    The guard is a fork of mlaunch, so it would match ``pkill -9 -f mlaunch`` and die with it,
    leaving the run to nobody. The kernel shows /proc/<pid>/cmdline from the argv memory
    (arg_start..arg_end in /proc/self/stat), which a process may rewrite through /proc/self/mem;
    the new title is cut to the length of the old command line.
    """
    try:
        with open("/proc/self/comm", "w") as f:
            f.write(title[:15])
        stat = read_file("/proc/self/stat")
        fields = stat[stat.rfind(b")") + 2 :].split()
        start, end = int(fields[45]), int(fields[46])  # stat fields 48 and 49
        if end <= start:
            return
        data = title.encode()[: end - start - 1].ljust(end - start, b"\0")
        fd = os.open("/proc/self/mem", os.O_RDWR)
        try:
            os.pwrite(fd, data, start)
        finally:
            os.close(fd)
    except (OSError, ValueError, IndexError):
        pass  # an old or locked-down kernel: the guard keeps mlaunch's command line


def _send(pid: int, sig: int) -> None:
    try:
        os.kill(pid, sig)
    except OSError:
        pass


def _remove_file(path: bytes) -> None:
    """Remove ``path`` and its folder if that is left empty."""
    try:
        os.unlink(path)
        os.rmdir(os.path.dirname(path))
    except OSError:
        pass


def _remove_temp_dir(temp_dir: str | None) -> bool:
    if not temp_dir or not os.path.isdir(temp_dir):
        return False
    import shutil

    shutil.rmtree(temp_dir, ignore_errors=True)
    return not os.path.exists(temp_dir)
