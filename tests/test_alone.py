"""The lock that runs serial tests alone (tests/alone.py): shared for the others, exclusive for a
serial test, kept from one serial test for the next on the same worker, never kept for good."""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import threading
from pathlib import Path

import alone
import pytest
from procutil import wait_until


def _room_is_free(folder: Path) -> bool:
    """Whether another worker's test could take the room now (a shared lock, not waiting)."""
    fd = os.open(folder / "serial-room.lock", os.O_CREAT | os.O_RDWR, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False
    finally:
        os.close(fd)


def test_a_serial_turn_excludes_the_others_and_ends_with_it(tmp_path: Path) -> None:
    with alone.turn(tmp_path, serial=True):
        assert not _room_is_free(tmp_path)
    assert _room_is_free(tmp_path)
    with alone.turn(tmp_path, serial=False):
        assert _room_is_free(tmp_path)  # shared: the other tests run together


def _other_worker(folder: Path) -> subprocess.Popen[bytes]:
    """Another worker's test that is not serial: a process of its own, as xdist's workers are."""
    code = (
        "import sys; from pathlib import Path; import alone\n"
        "with alone.turn(Path(sys.argv[1]), serial=False):\n"
        "    pass\n"
    )
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parent)}
    return subprocess.Popen([sys.executable, "-c", code, str(folder)], env=env)


def _waits_on_a_lock(pid: int) -> bool:
    """Whether ``pid`` is blocked on a file lock (/proc/locks lists a waiter with '->')."""
    lines = Path("/proc/locks").read_text().splitlines()
    return any("->" in line and str(pid) in line.split() for line in lines)


def test_a_serial_turn_keeps_the_lock_for_the_next_serial_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(alone, "KEEP_SECONDS", 600.0)
    with alone.turn(tmp_path, serial=True, keep=True):
        pass
    assert not _room_is_free(tmp_path)  # kept between the two serial tests
    other = _other_worker(tmp_path)
    try:
        assert wait_until(lambda: _waits_on_a_lock(other.pid), 30)
        with alone.turn(tmp_path, serial=True):  # the next serial test, before the other one
            assert other.poll() is None and _waits_on_a_lock(other.pid)
        assert other.wait(30) == 0
    finally:
        if other.poll() is None:
            other.kill()
            other.wait()
    assert _room_is_free(tmp_path)


def test_a_kept_lock_goes_back_when_no_serial_test_comes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(alone, "KEEP_SECONDS", 0.2)
    with alone.turn(tmp_path, serial=True, keep=True):
        pass
    assert not _room_is_free(tmp_path)
    assert wait_until(lambda: _room_is_free(tmp_path), 30)


def test_a_test_that_is_not_serial_gives_back_a_kept_lock_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(alone, "KEEP_SECONDS", 600.0)
    entered = threading.Event()

    def next_test() -> None:  # the worker's next test: it would wait on its own worker's lock
        with alone.turn(tmp_path, serial=False):
            entered.set()

    with alone.turn(tmp_path, serial=True, keep=True):
        pass
    threading.Thread(target=next_test, daemon=True).start()
    assert entered.wait(30)
    assert _room_is_free(tmp_path)


class _Item:
    def __init__(self, name: str, serial: bool) -> None:
        self.name = name
        self.serial = serial

    def get_closest_marker(self, name: str) -> object:
        return object() if self.serial and name == alone.MARKER else None


def test_the_serial_tests_are_collected_first_and_the_rest_keep_their_order() -> None:
    import conftest

    items = [_Item("a", False), _Item("s1", True), _Item("b", False), _Item("s2", True)]
    conftest.pytest_collection_modifyitems(None, items)  # type: ignore[arg-type]
    assert [item.name for item in items] == ["s1", "s2", "a", "b"]
