"""A cgroup v2 per run, where the system allows one: the run's processes without any marker.

The marker (``MLAUNCH_RUN_ID``) is lost by a daemon that clears its environment, and the
subreaper only holds while mlaunch lives. A cgroup holds every descendant whatever it does:
mlaunch makes ``mlaunch-<pid>-<random>`` below its own cgroup and moves itself into it once the
guard is forked (the guard stays outside), so everything started from then on, at any depth, in
any session, is a member. ``members()`` lists them and ``kill()`` ends them all at once with
``cgroup.kill`` (Linux 5.14; before that, SIGKILL to each member until none is left).

Where there is no cgroup2 mount, no permission to write there (a systemd session scope belongs
to root; a user's own ``user@.service`` tree is delegated), or ``MLAUNCH_CGROUP=0``,
``RunCgroup.create`` says why not and mlaunch relies on the marker and the subreaper, as before.
"""

from __future__ import annotations

import _thread
import os
import signal
import time

PREFIX = "mlaunch-"
# How long leave() waits for a killed cgroup to empty before removing it.
EMPTY_WAIT = 1.0


def cgroup2_root() -> str | None:
    """Where cgroup2 is mounted (/sys/fs/cgroup, or /sys/fs/cgroup/unified on hybrid systems)."""
    try:
        with open("/proc/self/mountinfo", "rb") as f:
            lines = f.read().splitlines()
    except OSError:
        return None
    for line in lines:
        left, sep, right = line.partition(b" - ")
        if sep and right.split(b" ", 1)[0] == b"cgroup2":
            return left.split(b" ")[4].decode("utf-8", "surrogateescape")
    return None


def own_cgroup(pid: int | str = "self") -> str | None:
    """This process's cgroup v2 path (``0::/...``), relative to the cgroup2 mount."""
    try:
        with open(f"/proc/{pid}/cgroup", "rb") as f:
            lines = f.read().splitlines()
    except OSError:
        return None
    for line in lines:
        if line.startswith(b"0::"):
            return line[3:].decode("utf-8", "surrogateescape")
    return None


class RunCgroup:
    """One run's cgroup: ``path`` (the directory) below ``parent`` (where mlaunch was)."""

    def __init__(self, path: str, parent: str) -> None:
        self.path = path
        self.parent = parent
        self.entered = False
        self._moving: _thread.LockType | None = None  # held while enter_soon's thread moves us

    @classmethod
    def create(cls, environ: os._Environ[str] | dict[str, str]) -> tuple[RunCgroup | None, str]:
        """(the run's new cgroup, "") or (None, why there is none)."""
        if environ.get("MLAUNCH_CGROUP", "1").lower() in ("0", "off", "false", "no"):
            return None, "MLAUNCH_CGROUP=0"
        root = cgroup2_root()
        if root is None:
            return None, "no cgroup2 file system is mounted"
        mine = own_cgroup()
        if mine is None:
            return None, "this process is in no cgroup v2"
        parent = os.path.join(root, mine.lstrip("/"))
        _remove_stale(parent)
        path = os.path.join(parent, f"{PREFIX}{os.getpid()}-{os.urandom(4).hex()}")
        try:
            os.mkdir(path, 0o755)
        except OSError as e:
            return None, f"cannot make a cgroup in {parent}: {e.strerror}"
        return cls(path, parent), ""

    def enter(self, pid: int = 0) -> bool:
        """Move ``pid`` (0: this process, with all its threads) into the run's cgroup."""
        if _write(os.path.join(self.path, "cgroup.procs"), str(pid or os.getpid())):
            self.entered = True
        return self.entered

    def enter_soon(self) -> None:
        """Move this process into the run's cgroup in a thread of its own (``settle`` waits).

        Writing cgroup.procs waits for an RCU grace period in the kernel (milliseconds of wall
        time, no CPU, the GIL released): the program goes on meanwhile. A bare _thread, not
        threading: nothing else needs it this early.
        """
        moving = _thread.allocate_lock()
        moving.acquire()
        self._moving = moving

        def move() -> None:
            try:
                self.enter()
            finally:
                moving.release()

        _thread.start_new_thread(move, ())

    def move_soon(self, pids: list[int]) -> None:
        """Move ``pids`` into the run's cgroup once this process's own move is done, in a
        thread of its own (``settle`` waits for both): children the quick start
        (mlaunch.app.quick) started while that move was under way began outside it."""
        before = self._moving
        moving = _thread.allocate_lock()
        moving.acquire()
        self._moving = moving
        procs = os.path.join(self.path, "cgroup.procs")

        def move() -> None:
            try:
                if before is not None:
                    before.acquire()
                    before.release()
                for pid in pids:
                    _write(procs, str(pid))  # one that has ended already cannot move: gone
            finally:
                moving.release()

        _thread.start_new_thread(move, ())

    def settle(self) -> bool:
        """Wait for ``enter_soon``'s move; whether this process is in the run's cgroup."""
        moving = self._moving
        if moving is not None:
            moving.acquire()
            moving.release()
            self._moving = None
        return self.entered

    def members(self) -> list[int]:
        """Every process in the run's cgroup now (mlaunch itself included, while inside)."""
        try:
            with open(os.path.join(self.path, "cgroup.procs"), "rb") as f:
                return [int(word) for word in f.read().split()]
        except (OSError, ValueError):
            return []

    def populated(self) -> bool:
        try:
            with open(os.path.join(self.path, "cgroup.events"), "rb") as f:
                return b"populated 1" in f.read()
        except OSError:
            return bool(self.members())

    def kill(self) -> None:
        """SIGKILL every member at once, forks in flight included (never mlaunch: leave first)."""
        if _write(os.path.join(self.path, "cgroup.kill"), "1"):
            return
        me = os.getpid()
        for _ in range(100):  # no cgroup.kill (Linux < 5.14): one by one, until none is left
            pids = [pid for pid in self.members() if pid != me]
            if not pids:
                return
            for pid in pids:
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    pass

    def leave(self) -> None:
        """Move this process back where it was; kill what is left; remove the cgroup."""
        if self.entered:
            _write(os.path.join(self.parent, "cgroup.procs"), str(os.getpid()))
            self.entered = False
        self.remove()

    def remove(self) -> bool:
        """rmdir the cgroup, killing what is still in it; whether it is gone."""
        deadline = time.monotonic() + EMPTY_WAIT
        while True:
            try:
                os.rmdir(self.path)
                return True
            except FileNotFoundError:
                return True
            except OSError:
                pass  # EBUSY: members left (or mlaunch itself, if leaving failed)
            if time.monotonic() >= deadline:
                return False
            self.kill()
            time.sleep(0.005)


def _remove_stale(parent: str) -> None:
    """Remove the empty cgroups of runs whose mlaunch is gone (it and its guard were killed).

    Only empty ones: rmdir fails on a cgroup with members, and those are never touched.
    """
    try:
        names = [n for n in os.listdir(parent) if n.startswith(PREFIX)]
    except OSError:
        return
    for name in names:
        pid = name[len(PREFIX) :].partition("-")[0]
        if pid.isdigit() and not os.path.exists(f"/proc/{pid}"):
            try:
                os.rmdir(os.path.join(parent, name))
            except OSError:
                pass


def _write(path: str, text: str) -> bool:
    try:
        fd = os.open(path, os.O_WRONLY)
    except OSError:
        return False
    try:
        os.write(fd, text.encode())
        return True
    except OSError:
        return False
    finally:
        os.close(fd)
