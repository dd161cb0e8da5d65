"""How the benchmarks observe processes from outside without disturbing them.

- ReadyProbe: a FIFO every benchmark child opens as fd 3, writes one line to once it runs, and
  holds open (through its ``exec sleep``) while it lives. The harness blocks in select() on the
  read end, so it costs nothing while it waits and time-stamps each line on arrival; EOF means
  every child is gone (the harness's own write end is closed first).
- Launched: a process started with a pidfd, so its exit is one more fd in the same select().
- /proc readers: CPU seconds (``stat`` for whole processes, ``schedstat`` in ns for one thread),
  peak RSS (``VmHWM``), read without stopping the process.
"""

from __future__ import annotations

import ctypes
import errno
import os
import select
import signal
import subprocess
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

CLK_TCK = os.sysconf("SC_CLK_TCK")


class BenchError(Exception):
    """A measured command did not behave (failed to start, exited early, timed out)."""


# --- processes ------------------------------------------------------------------------------


@dataclass
class Launched:
    """A process the harness started: its Popen, a pidfd for select(), when it was exec'd."""

    popen: subprocess.Popen[bytes]
    pidfd: int
    started: float
    exited_at: float | None = None
    returncode: int | None = None

    @property
    def pid(self) -> int:
        return self.popen.pid

    def poll_exit(self) -> bool:
        """Reap it if it has exited (time-stamped when first seen); True once reaped."""
        if self.returncode is not None:
            return True
        pid, status = os.waitpid(self.pid, os.WNOHANG)
        if pid == 0:
            return False
        if self.exited_at is None:
            self.exited_at = time.perf_counter()
        self._reaped(status)
        return True

    def wait_exit_keep_zombie(self, deadline: float) -> float:
        """Block until it exits (zombie kept so /proc still answers); the exit time."""
        if not wait_readable([self.pidfd], deadline):
            raise BenchError(f"pid {self.pid} did not exit in time")
        if self.exited_at is None:
            self.exited_at = time.perf_counter()
        os.waitid(os.P_PID, self.pid, os.WEXITED | os.WNOWAIT)
        return self.exited_at

    def reap(self, deadline: float) -> int:
        if self.returncode is None:
            if not wait_readable([self.pidfd], deadline):
                raise BenchError(f"pid {self.pid} did not exit in time")
            if self.exited_at is None:
                self.exited_at = time.perf_counter()
            _, status = os.waitpid(self.pid, 0)
            self._reaped(status)
        assert self.returncode is not None
        return self.returncode

    def _reaped(self, status: int) -> None:
        self.returncode = os.waitstatus_to_exitcode(status)
        self.popen.returncode = self.returncode  # so Popen never waits for the pid again

    def kill(self) -> None:
        """End it and its process group at once (cleanup path)."""
        if self.returncode is None:
            for target in (lambda: os.killpg(self.pid, signal.SIGKILL), self.popen.kill):
                try:
                    target()
                except (ProcessLookupError, PermissionError):
                    pass
            try:
                _, status = os.waitpid(self.pid, 0)
                self._reaped(status)
            except ChildProcessError:
                self.returncode = -9
        self.close()

    def close(self) -> None:
        if self.pidfd >= 0:
            os.close(self.pidfd)
            self.pidfd = -1
        for pipe in (self.popen.stdout, self.popen.stderr):
            if pipe is not None:
                pipe.close()


def launch(
    argv: Sequence[str],
    env: Mapping[str, str],
    *,
    stdout: int | None = None,
    stderr: int | None = None,
    stdin: int | None = subprocess.DEVNULL,
    cwd: str | None = None,
) -> Launched:
    """Start ``argv`` in a session of its own (so cleanup can end its group) with a pidfd.

    ``started`` is taken just before the fork: what is measured is from exec of the command.
    """
    started = time.perf_counter()
    popen = subprocess.Popen(
        list(argv),
        env=dict(env),
        stdin=stdin,
        stdout=stdout,
        stderr=stderr,
        cwd=cwd,
        start_new_session=True,
    )
    return Launched(popen, os.pidfd_open(popen.pid), started)


def wait_readable(fds: Sequence[int], deadline: float) -> list[int]:
    """The fds readable before ``deadline`` (perf_counter time), [] on timeout."""
    while True:
        left = deadline - time.perf_counter()
        if left <= 0:
            return []
        ready, _, _ = select.select(list(fds), [], [], left)
        if ready:
            return ready


def become_subreaper() -> bool:
    """Orphaned descendants come back to the harness, so cleanup can always find them."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return int(libc.prctl(36, 1, 0, 0, 0)) == 0  # PR_SET_CHILD_SUBREAPER
    except (OSError, AttributeError):
        return False


def kill_descendants() -> int:
    """SIGKILL every process below the harness (and reap them); how many there were."""
    import psutil

    me = psutil.Process()
    try:
        children = me.children(recursive=True)
    except psutil.Error:
        children = []
    for child in children:
        try:
            child.kill()
        except psutil.Error:
            pass
    psutil.wait_procs(children, timeout=5.0)
    while True:  # orphans re-parented to us (we are their subreaper)
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            break
        if pid == 0:
            break
    return len(children)


def find_descendant(root: int, match: Callable[[list[str]], bool]) -> int | None:
    """The pid of the first live descendant of ``root`` whose argv satisfies ``match``."""
    import psutil

    try:
        children = psutil.Process(root).children(recursive=True)
    except psutil.Error:
        return None
    for child in children:
        try:
            if child.status() != psutil.STATUS_ZOMBIE and match(child.cmdline()):
                return int(child.pid)
        except psutil.Error:
            continue
    return None


# --- /proc ----------------------------------------------------------------------------------


def cpu_seconds(pid: int) -> float:
    """User + system CPU of the whole process (every thread, dead ones too), 10 ms ticks."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def fine_cpu_seconds(pid: int) -> float:
    """CPU of the live threads in ns resolution (schedstat); ``cpu_seconds`` where missing."""
    total = 0
    try:
        for tid in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{tid}/schedstat") as f:
                total += int(f.read().split()[0])
    except (FileNotFoundError, ValueError, IndexError):
        return cpu_seconds(pid)
    return total / 1e9


def _ticks(stat_path: str) -> int:
    with open(stat_path) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])


def process_cpu(pid: int) -> float:
    """CPU seconds of one process: its live threads in ns, those that ended in ticks."""
    live_ns = live_ticks = 0
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/schedstat") as f:
                live_ns += int(f.read().split()[0])
            live_ticks += _ticks(f"/proc/{pid}/task/{tid}/stat")
        except (FileNotFoundError, ProcessLookupError):
            continue  # ended between listdir and open: its time is in the ticks below
    dead = max(0, _ticks(f"/proc/{pid}/stat") - live_ticks)
    return live_ns / 1e9 + dead / CLK_TCK


def descendants(pid: int) -> list[int]:
    """Every live descendant of pid (children lists of every thread, recursively)."""
    found: list[int] = []
    todo = [pid]
    while todo:
        parent = todo.pop()
        try:
            tids = os.listdir(f"/proc/{parent}/task")
        except FileNotFoundError:
            continue
        for tid in tids:
            try:
                with open(f"/proc/{parent}/task/{tid}/children") as f:
                    kids = [int(k) for k in f.read().split()]
            except FileNotFoundError:
                continue
            found.extend(kids)
            todo.extend(kids)
    return found


def launcher_cpu(pid: int) -> float:
    """CPU seconds of the launcher and its descendants running the same executable."""
    total = process_cpu(pid)
    exe = os.readlink(f"/proc/{pid}/exe")
    for kid in descendants(pid):
        try:
            if os.readlink(f"/proc/{kid}/exe") == exe:
                total += process_cpu(kid)
        except (FileNotFoundError, PermissionError):
            continue
    return total


def vm_hwm_mb(pid: int) -> float:
    """Peak resident set size so far (VmHWM), in MB (10^6 bytes)."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024 / 1e6
    raise BenchError(f"no VmHWM in /proc/{pid}/status")


# --- the ready/alive FIFO -------------------------------------------------------------------


@dataclass
class ReadyProbe:
    """The FIFO the benchmark children report on (see the module docstring)."""

    path: Path
    rfd: int = -1
    wfd: int = -1
    lines: int = 0
    first: float | None = None
    arrivals: list[float] = field(default_factory=list)

    def open(self) -> ReadyProbe:
        if self.path.exists():
            self.path.unlink()
        os.mkfifo(self.path)
        self.rfd = os.open(self.path, os.O_RDONLY | os.O_NONBLOCK)
        # Our own writer keeps read() from seeing EOF before any child has connected.
        self.wfd = os.open(self.path, os.O_WRONLY | os.O_NONBLOCK)
        return self

    def _read(self) -> bool:
        """Take what is there; False at EOF (no writer left)."""
        try:
            data = os.read(self.rfd, 65536)
        except BlockingIOError:
            return True
        if not data:
            return False
        now = time.perf_counter()
        count = data.count(b"\n")
        if count and self.first is None:
            self.first = now
        self.lines += count
        self.arrivals.extend([now] * count)
        return True

    def wait_ready(self, n: int, proc: Launched, deadline: float) -> tuple[float, float]:
        """Times (perf_counter) the first and the n-th child said they were running."""
        while self.lines < n:
            ready = wait_readable([self.rfd, proc.pidfd], deadline)
            if not ready:
                raise BenchError(f"only {self.lines} of {n} children running before the deadline")
            if self.rfd in ready:
                self._read()
            elif proc.pidfd in ready:
                self._read()
                if self.lines < n:
                    raise BenchError(
                        f"the launcher exited after starting {self.lines} of {n} children"
                    )
        assert self.first is not None
        return self.first, self.arrivals[n - 1]

    def release(self) -> None:
        """Close our writer: from now on EOF means every child has gone."""
        if self.wfd >= 0:
            os.close(self.wfd)
            self.wfd = -1

    def wait_gone(self, deadline: float) -> float:
        """When the last child holding the FIFO exited (perf_counter)."""
        self.release()
        while True:
            if not wait_readable([self.rfd], deadline):
                raise BenchError("benchmark children still alive at the deadline")
            if not self._read():
                return time.perf_counter()

    def close(self) -> None:
        self.release()
        if self.rfd >= 0:
            os.close(self.rfd)
            self.rfd = -1
        try:
            self.path.unlink()
        except FileNotFoundError:
            pass


def stop_and_time(
    proc: Launched, probe: ReadyProbe, sig: int, timeout: float, group: bool = False
) -> float:
    """Send ``sig`` to the launcher (``group``: to its process group, as a terminal sends
    Ctrl-C to the foreground group); seconds until it and every descendant are gone.

    The benchmark children are seen on the FIFO, the launcher through its pidfd, and any other
    descendant (mlaunch's guard process, an orphan) after the launcher's exit: the harness is
    their subreaper, so they are then its own children.
    """
    deadline = time.perf_counter() + timeout
    probe.release()
    sent = time.perf_counter()
    if group:
        os.killpg(proc.pid, sig)  # started in a session of its own: its group is its pid
    else:
        os.kill(proc.pid, sig)
    gone = probe.wait_gone(deadline)
    proc.reap(deadline)
    assert proc.exited_at is not None
    return max(gone, proc.exited_at, wait_no_children(deadline)) - sent


def wait_no_children(deadline: float, poll: float = 0.0005) -> float:
    """When the harness had no child left (reaping as they exit); polls /proc/self only."""
    me = os.getpid()
    path = f"/proc/{me}/task/{me}/children"
    while True:
        try:
            while os.waitpid(-1, os.WNOHANG)[0]:
                pass
        except ChildProcessError:
            return time.perf_counter()
        try:
            with open(path) as f:
                if not f.read().split():
                    return time.perf_counter()
        except FileNotFoundError:  # no CONFIG_PROC_CHILDREN: waitpid above is the only judge
            pass
        if time.perf_counter() > deadline:
            raise BenchError("a descendant of the launcher outlived it past the deadline")
        time.sleep(poll)  # only after the launcher has exited: nothing left to disturb


def read_pipe_until_exit(
    fd: int,
    proc: Launched,
    deadline: float,
    on_chunk: Callable[[bytes, float], None],
) -> None:
    """Feed each chunk of ``fd`` to ``on_chunk`` until EOF and the process has exited."""
    os.set_blocking(fd, False)
    open_fds = [fd, proc.pidfd]
    while open_fds:
        ready = wait_readable(open_fds, deadline)
        if not ready:
            raise BenchError("the measured command did not finish in time")
        now = time.perf_counter()
        if proc.pidfd in ready:
            if proc.exited_at is None:
                proc.exited_at = now
            open_fds.remove(proc.pidfd)
        if fd in ready:
            try:
                data = os.read(fd, 1 << 20)
            except BlockingIOError:
                continue
            except OSError as e:
                if e.errno != errno.EIO:
                    raise
                data = b""
            if not data:
                open_fds.remove(fd)
                continue
            on_chunk(data, now)
