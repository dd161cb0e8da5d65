"""A run's private folder (params files) and the sweep of folders whose run was killed outright.

Each run makes ``$TMPDIR/mlaunch-PID-XXXXXXXX`` (mode 0700) and holds an ``flock`` on it for its
whole life. Normally mlaunch removes it at exit, or its guard does when mlaunch dies. When both
are killed with SIGKILL nobody does, so a later run's guard sweeps: it removes a folder of this
user's only when its PID is gone *and* nobody holds its lock (the lock also protects a live run
whose PID is not visible here, in another PID namespace sharing /tmp). The lock goes with the
last descriptor of it, which only mlaunch has (exec'd children do not inherit it; the guard
closes its copy).
"""

from __future__ import annotations

import os

# Matched in the guard's sweep only (re's cache compiles it there, not before the first child).
_NAME = r"mlaunch-([0-9]+)-[0-9a-f]{8}"
_locks: dict[str, int] = {}  # this process's private folders -> the descriptor holding the lock


def temp_base() -> str:
    return os.environ.get("TMPDIR") or "/tmp"


def private_temp_dir() -> str:
    """A directory only this user can read, for params files (tempfile costs ~4 ms to import)."""
    import fcntl

    base = temp_base()
    for _ in range(100):
        path = os.path.join(base, f"mlaunch-{os.getpid()}-{os.urandom(4).hex()}")
        try:
            os.mkdir(path, 0o700)
        except FileExistsError:
            continue
        fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # a new folder: nobody else has it
        _locks[path] = fd
        return path
    raise OSError(f"cannot create a private directory in {base}")


def remove_private_dir(path: str) -> None:
    """Remove the params-file folder: flat, so no shutil (2 ms to import at exit)."""
    try:
        _remove_tree(path)
    finally:
        fd = _locks.pop(path, None)
        if fd is not None:
            os.close(fd)


def _remove_tree(path: str) -> None:
    try:
        entries = list(os.scandir(path))
    except FileNotFoundError:
        return
    if any(e.is_dir(follow_symlinks=False) for e in entries):
        import shutil

        shutil.rmtree(path, ignore_errors=True)
        return
    for entry in entries:
        try:
            os.unlink(entry.path)
        except FileNotFoundError:
            pass
    try:
        os.rmdir(path)
    except OSError:
        pass


def sweep_dead_runs(base: str | None = None) -> list[str]:
    """Remove the private folders of this user's runs that died with their guard; the paths."""
    import fcntl
    import re  # here, in the guard: not on mlaunch's way to its first child (the quick start)

    base = base or temp_base()
    try:
        names = [n for n in os.listdir(base) if n.startswith("mlaunch-")]
    except OSError:
        return []
    removed = []
    uid = os.getuid()
    for name in names:
        m = re.fullmatch(_NAME, name)
        if m is None or _alive(int(m.group(1))):
            continue
        path = os.path.join(base, name)
        try:
            fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        except OSError:
            continue  # gone, a symlink, not a folder
        try:
            if os.fstat(fd).st_uid != uid:
                continue  # another user's: never touched
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:  # BlockingIOError: a live run holds it
            os.close(fd)
            continue
        try:
            _remove_tree(path)
            removed.append(path)
        finally:
            os.close(fd)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # EPERM: someone else's process
    return True
