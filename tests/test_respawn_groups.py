"""A respawned process's dead instance takes what it left in its process group with it
(issue 38, item 14): each respawn used to leave the old instance's grandchildren running until
the run ended."""

from __future__ import annotations

import signal
from pathlib import Path

from procutil import wait_until
from test_faults import Mlaunch, alive, proc, write_launch

# Starts a grandchild in its own process group (a `sleep` it never waits for), says its pid in a
# file of the folder, and exits 1: respawned after 0.2 s, again and again.
LEAVES_A_CHILD = """\
import os, subprocess, sys
child = subprocess.Popen(['sleep', '1000'])
open(os.path.join(sys.argv[1], f'gc-{child.pid}'), 'w').close()
sys.exit(1)
"""


def grandchildren(folder: Path) -> list[int]:
    return sorted(int(p.name[3:]) for p in folder.glob("gc-*"))


def test_a_respawn_ends_what_the_dead_instance_left_in_its_group(tmp_path: Path) -> None:
    folder = tmp_path / "pids"
    folder.mkdir()
    entry = proc(LEAVES_A_CHILD, "leaver", respawn=True, respawn_delay=0.2)
    entry = entry.replace("PY, '-c', ", "PY, '-c', ").replace(
        "], name=", f", {str(folder)!r}], name="
    )
    m = Mlaunch(tmp_path, write_launch(tmp_path, [entry]))
    try:
        assert wait_until(lambda: len(grandchildren(folder)) >= 3, 30), "\n".join(m.lines)
        first = grandchildren(folder)[0]
        # Before: alive until the run ended. Now: SIGTERM at once (sleep dies of it).
        assert wait_until(lambda: not alive(first), 15), "\n".join(m.lines)
        assert any("ending what the exited instance left in its process group" in line
                   for line in m.lines), "\n".join(m.lines)  # fmt: skip
        m.popen.send_signal(signal.SIGINT)
        m.wait()
    finally:
        m.close()
    assert not any(alive(pid) for pid in grandchildren(folder))
