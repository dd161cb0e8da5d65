"""The same 30 KB/s terminal as tests/test_faults_slow_terminal.py, but a real one: a pty, whose
kernel reports no queued bytes (TIOCOUTQ of a pty's slave is always 0), so mlaunch measures
the reader by the time of its writes instead. A quiet line arrived 1.45-1.6 s behind the flood
(worst 2.7 s); the README promises half a second. The pty's master is read at a fixed pace by
a thread (the terminal).
"""

from __future__ import annotations

import os
import pty
import re
import statistics
from pathlib import Path

import pytest
from test_faults import Mlaunch, proc, write_launch
from test_faults_output import PacedReader
from test_faults_slow_terminal import FLOOD, QUIET, SECONDS

ANSI = re.compile(rb"\x1b\[[0-9;]*m")


@pytest.mark.serial  # a quiet line's lag, in seconds
def test_a_quiet_line_is_half_a_second_behind_a_flood_on_a_30_kb_s_pty(tmp_path: Path) -> None:
    master, slave = pty.openpty()
    reader = PacedReader(master, 3000, 0.1)  # 30 KB/s
    reader.start()
    launch = write_launch(tmp_path, [proc(FLOOD, "flood"), proc(QUIET, "quiet")])
    m = Mlaunch(tmp_path, launch, stdout=slave)
    os.close(slave)
    try:
        assert m.wait(timeout=60) == 0, m.stderr()
    finally:
        m.close()
        reader.join(30)
        os.close(master)
    delays, notices = [], 0
    for arrived, line in reader.arrivals:
        line = ANSI.sub(b"", line.rstrip(b"\r"))  # the terminal's end of line, and colours
        if b"[quiet" in line and b"] q " in line:
            *_, stamp = line.split()
            delays.append(arrived - float(stamp))
        notices += b"the terminal fell behind" in line
    assert len(delays) == SECONDS, "the quiet child lost lines on the screen"
    # The first two lines may come while the reader's pace is measured (its buffer full).
    settled = delays[2:]
    print(f"quiet lines behind a flood on a 30 KB/s pty: {[round(d, 3) for d in delays]}")
    assert max(delays) < 1.5, f"a quiet line waited {max(delays):.2f} s behind the flood"
    assert statistics.median(settled) < 0.5, f"quiet lines waited {settled} behind the flood"
    assert max(settled) < 0.8, f"a quiet line waited {max(settled):.2f} s behind the flood"
    assert notices >= 1, "lines were dropped from the screen without a word"
