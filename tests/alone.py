"""Tests marked ``serial`` run alone when the suite runs on several pytest-xdist workers.

They measure time (a quiet line's lag behind a flood, a topic's rate, how long Ctrl-C takes):
with three other workers' launches competing for two cores, those figures would say more about
the neighbours than about mlaunch. Every other test holds a shared lock while it runs and a
serial test holds it exclusively, so a serial test starts once the tests already running have
finished and nothing else starts until it is done. Without xdist there is one test at a time
anyway, and no lock is taken.

The lock prefers the serial test: a shared holder passes through a gate first, and the serial
test keeps the gate closed while it waits, so a stream of new tests cannot starve it. Each worker
holds at most one of these locks at a time, so they cannot deadlock. The files live in the run's
base temp folder (shared by its workers, removed with old runs by pytest), so two runs on one
machine never wait on each other.

Each time a serial test takes the lock it waits for every running test to end: that drain leaves
workers idle. So the serial tests are collected first (conftest.py), one after the other, and a
worker that runs one whose next test is serial too keeps the lock for it: the serial tests drain
the run once, not once each. The lock it keeps goes back after ``KEEP_SECONDS`` if the next test
does not come for it (another worker took it): kept for good, that worker could wait on it.
"""

from __future__ import annotations

import fcntl
import os
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

MARKER = "serial"  # registered in pyproject.toml
# How long a worker keeps the lock for its next serial test (a test's setup, not its run).
KEEP_SECONDS = 5.0


def lock_folder(config: pytest.Config) -> Path | None:
    """The folder the run's workers share, or None when this is not an xdist worker."""
    if not hasattr(config, "workerinput"):
        return None
    # xdist gives each worker --basetemp=<the run's base temp>/popen-gwN.
    return Path(config.option.basetemp).parent


@contextmanager
def _locked(path: Path, operation: int) -> Iterator[None]:
    fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o600)
    try:
        fcntl.flock(fd, operation)
        yield
    finally:
        os.close(fd)  # closing releases the lock


class _Kept:
    """The exclusive lock a serial test left for the next one on this worker: the gate's and the
    room's fds, closed (released) by the next non-serial turn, by the next serial one that does
    not keep it, or by a timer."""

    def __init__(self) -> None:
        self._mutex = threading.Lock()
        self._fds: tuple[int, int] | None = None
        self._timer: threading.Timer | None = None

    def take(self) -> tuple[int, int] | None:
        """The kept fds, now the caller's to close (None when nothing is kept)."""
        with self._mutex:
            fds, self._fds = self._fds, None
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None
            return fds

    def keep(self, fds: tuple[int, int], seconds: float) -> None:
        with self._mutex:
            self._fds = fds
            self._timer = threading.Timer(seconds, self.release)
            self._timer.daemon = True
            self._timer.start()

    def release(self) -> None:
        fds = self.take()
        for fd in fds or ():
            os.close(fd)  # closing releases the lock


_kept = _Kept()


@contextmanager
def turn(folder: Path, serial: bool, keep: bool = False) -> Iterator[None]:
    """Hold the run's lock for one test: exclusively when ``serial``, else shared.

    ``keep`` (a serial test whose next test is serial too): the exclusive lock is kept for that
    test, at most ``KEEP_SECONDS``.
    """
    gate, room = folder / "serial-gate.lock", folder / "serial-room.lock"
    if serial:
        fds = _kept.take()
        if fds is None:
            gate_fd = os.open(gate, os.O_CREAT | os.O_RDWR, 0o600)
            room_fd = os.open(room, os.O_CREAT | os.O_RDWR, 0o600)
            fds = (gate_fd, room_fd)
            try:
                fcntl.flock(gate_fd, fcntl.LOCK_EX)
                fcntl.flock(room_fd, fcntl.LOCK_EX)
            except BaseException:
                for fd in fds:
                    os.close(fd)
                raise
        try:
            yield
        except BaseException:
            keep = False
            raise
        finally:
            if keep:
                _kept.keep(fds, KEEP_SECONDS)
            else:
                for fd in fds:
                    os.close(fd)
        return
    _kept.release()
    fd = os.open(room, os.O_CREAT | os.O_RDWR, 0o600)
    try:
        with _locked(gate, fcntl.LOCK_EX):
            fcntl.flock(fd, fcntl.LOCK_SH)
        yield
    finally:
        os.close(fd)
