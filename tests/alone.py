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
"""

from __future__ import annotations

import fcntl
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

MARKER = "serial"  # registered in pyproject.toml


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


@contextmanager
def turn(folder: Path, serial: bool) -> Iterator[None]:
    """Hold the run's lock for one test: exclusively when ``serial``, else shared."""
    gate, room = folder / "serial-gate.lock", folder / "serial-room.lock"
    if serial:
        with _locked(gate, fcntl.LOCK_EX), _locked(room, fcntl.LOCK_EX):
            yield
        return
    fd = os.open(room, os.O_CREAT | os.O_RDWR, 0o600)
    try:
        with _locked(gate, fcntl.LOCK_EX):
            fcntl.flock(fd, fcntl.LOCK_SH)
        yield
    finally:
        os.close(fd)
