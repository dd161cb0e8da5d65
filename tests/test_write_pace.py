"""WritePace: a pty's reader measured by the time of writes, on a fake clock (the end-to-end
lag is tests/test_faults_slow_pty.py's)."""

from __future__ import annotations

import os
import pty
from collections.abc import Iterator

import pytest

from mlaunch.engine.screen import (
    MAX_AHEAD,
    MEASURED_SHARE,
    UNKNOWN_AHEAD,
    WINDOW,
    Screen,
    WritePace,
)

# Tenths of a second of saturation that make one measuring window (and a little more).
TENTHS = int(WINDOW * 10) + 1


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def slave() -> Iterator[int]:
    master, slave = pty.openpty()
    yield slave
    os.close(slave)
    os.close(master)


def saturated(pace: WritePace, clock: Clock, per_tenth: int, tenths: int) -> None:
    """The pty blocks every write; the reader takes ``per_tenth`` bytes each 0.1 s."""
    for _ in range(tenths):
        clock.now += 0.1
        pace.wrote(per_tenth)
        pace.blocked()


def test_a_pty_gets_a_write_pace(slave: int) -> None:
    screen = Screen(slave)
    assert isinstance(screen.pace, WritePace)


def test_the_pace_is_what_the_pty_took_between_blocked_writes(slave: int) -> None:
    clock = Clock()
    pace = WritePace(slave, os.fstat(slave).st_mode, clock)
    assert pace.rate is None and pace.ahead == UNKNOWN_AHEAD
    for _ in range(8):  # writes it takes whole: it may keep up, and is given more each time
        pace.wrote(1000)
    assert pace.ahead == MAX_AHEAD
    pace.wrote(20_000)  # the buffer fills at once
    pace.blocked()
    assert pace.ahead == UNKNOWN_AHEAD and pace.room(pace.unread() or 0) > 1 << 20  # measuring
    saturated(pace, clock, 3000, TENTHS)  # 30 KB/s for a window
    assert pace.rate == pytest.approx(MEASURED_SHARE * 30_000)
    clock.now += 1.0
    assert pace.unread() == 0  # drained at the pace
    assert pace.room(0) == 4096  # 0.15 s of 24 KB/s, at least a page


def test_a_raise_that_overshoots_is_taken_back_and_a_slower_reader_measured_again(
    slave: int,
) -> None:
    clock = Clock()
    pace = WritePace(slave, os.fstat(slave).st_mode, clock)
    pace.blocked()
    saturated(pace, clock, 3000, TENTHS)
    measured = pace.rate
    assert measured is not None
    for _ in range(11):  # ten seconds of steady writes, never blocked
        clock.now += 1.0
        pace.wrote(100)
        pace.unread()
    assert pace.rate == pytest.approx(measured * 1.25)
    pace.blocked()  # too much: back
    assert pace.rate == pytest.approx(measured)
    clock.now += 1.0
    pace.wrote(100)
    pace.blocked()  # blocked again, not after a raise: the reader slowed down
    assert pace.rate is None and pace.ahead == UNKNOWN_AHEAD


def test_an_idle_pty_is_measured_afresh_and_a_fast_one_is_not_paced(slave: int) -> None:
    clock = Clock()
    pace = WritePace(slave, os.fstat(slave).st_mode, clock)
    pace.blocked()
    saturated(pace, clock, 3000, TENTHS)
    assert pace.rate is not None
    clock.now += 5.0
    pace.unread()
    assert pace.rate is None and pace.ahead == UNKNOWN_AHEAD  # idle: measured afresh
    pace.blocked()
    saturated(pace, clock, 500_000, TENTHS)  # 5 MB/s
    for _ in range(5):
        clock.now += 1.0
        pace.wrote(1)
        clock.now += 1.0
        pace.wrote(1)
        pace.unread()
    assert pace.rate is None and pace.ahead == MAX_AHEAD
