"""A crowd on the control socket (any process of the user's can connect, the launch's children
too) costs the run nothing it needs: idle connections never exhaust its descriptors (ctl is
still answered, a crashed process still respawns), and answers nobody reads are bounded.

The descriptor limit is made small in mlaunch's process (``prlimit``) rather than opening
thousands of connections.
"""

from __future__ import annotations

import json
import os
import re
import select
import socket
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_until

from mlaunch.parts.control_socket import Address

# What the run may hold of unread answers (control_socket.MAX_QUEUED).
MAX_QUEUED = 32 * 1024 * 1024

CRASHER = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(name='talker', output='screen',
            cmd=[sys.executable, '-c', 'import time; print("up", flush=True); time.sleep(600)']),
        ExecuteProcess(name='crasher', output='screen', respawn=True, respawn_delay=0.3,
            cmd=[sys.executable, '-c',
                 'import sys; open(sys.executable, "rb").close(); print("alive", flush=True);'
                 ' sys.stdin.readline(); sys.exit(3)']),
    ])
"""

FLOOD = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

CODE = '''
import sys, time
line = "x" * 199 + "\\\\n"
for i in range(20000):
    sys.stdout.write(line)
sys.stdout.write("flooded\\\\n"); sys.stdout.flush()
time.sleep(600)
'''

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(name='flood', output='log',
        cmd=[sys.executable, '-c', CODE])])
"""


def _socket(log: Path, pid: int) -> Path:
    def found() -> list[Path]:
        return list(log.glob(f"*-{pid}/control/ctl.sock"))

    assert wait_until(found, 30), list(log.iterdir())
    return found()[0]


def _connect(path: Path) -> socket.socket | None:
    """A connection to ``path`` without waiting (None when the run's queue is full)."""
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.setblocking(False)
    try:
        with Address(str(path)) as address:
            sock.connect(address)
    except (BlockingIOError, ConnectionRefusedError):
        sock.close()
        return None
    return sock


@pytest.fixture
def crowd() -> Iterator[list[socket.socket]]:
    held: list[socket.socket] = []
    yield held
    for sock in held:
        sock.close()


def _open_fds(pid: int) -> int:
    return len(os.listdir(f"/proc/{pid}/fd"))


def test_idle_connections_leave_ctl_and_respawn_working(
    tmp_path: Path, crowd: list[socket.socket]
) -> None:
    """300 idle connections to a run limited to 200 descriptors. It used to accept until
    EMFILE, then spin on the listening socket (95% CPU): ctl got no answer and the crashed
    process could not start again ("Too many open files")."""
    launch = tmp_path / "crasher.launch.py"
    launch.write_text(CRASHER)
    log = tmp_path / "log"
    env = clean_env(ROS_LOG_DIR=str(log))
    run = Running(["prlimit", "--nofile=200:200", *mlaunch(str(launch))], env=env)
    try:
        run.wait_for(r"\[talker-1\] up", 30)
        run.wait_for(r"\[crasher-\d+\] alive", 30)
        path = _socket(log, run.proc.pid)
        for _ in range(300):
            sock = _connect(path)
            if sock is not None:
                crowd.append(sock)
        assert wait_until(lambda: _open_fds(run.proc.pid) < 200 - 32, 10)
        done = run_mlaunch("ctl", "list", env=env)
        assert done.returncode == 0, done.stdout + done.stderr
        assert re.search(r"talker-1\s+running", done.stdout), done.stdout
        # The crashed process starts again: the supervisor still has descriptors to spawn with.
        seen = run.text.count("] alive")
        stop = run_mlaunch("ctl", "restart", "crasher", env=env)
        assert stop.returncode == 0, stop.stdout + stop.stderr
        assert wait_until(lambda: (run._pump(0.1), run.text.count("] alive"))[1] > seen, 30)
        assert "Too many open files" not in run.text and "internal error" not in run.text
    finally:
        run.kill()


def test_answers_nobody_reads_are_bounded(tmp_path: Path, crowd: list[socket.socket]) -> None:
    """60 clients ask for the last 10,000 lines (2 MB each) and never read: the run held
    every answer (+120 MB here; 200 clients took +742 MiB), now at most MAX_QUEUED in all; the
    rest are told to try again, and ctl is still answered."""
    launch = tmp_path / "flood.launch.py"
    launch.write_text(FLOOD)
    log = tmp_path / "log"
    env = clean_env(ROS_LOG_DIR=str(log))
    run = Running(mlaunch(str(launch)), env=env)
    try:
        path = _socket(log, run.proc.pid)
        logfile = path.parent.parent / "flood-1.log"
        assert wait_until(lambda: logfile.exists() and logfile.stat().st_size >= 3_900_000, 60)
        before = _rss(run.proc.pid)
        request = json.dumps({"version": 1, "op": "logs", "label": "flood", "lines": 10000})
        for _ in range(60):
            sock = _connect(path)
            assert sock is not None
            sock.send(request.encode() + b"\n")
            crowd.append(sock)

        def all_answered() -> bool:
            return all(select.select([s], [], [], 0)[0] for s in crowd)

        assert wait_until(all_answered, 60)
        grown = _rss(run.proc.pid) - before
        assert grown < MAX_QUEUED + 24 * 1024 * 1024, f"+{grown / 2**20:.0f} MiB"
        done = run_mlaunch("ctl", "list", env=env)
        assert done.returncode == 0, done.stdout + done.stderr
        refused = [s for s in crowd if b"try again" in s.recv(4096)]
        assert refused  # told, not silently dropped
    finally:
        run.kill()


def _rss(pid: int) -> int:
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise AssertionError("no VmRSS")
