"""The control socket against hostile and heavy clients, as real clients on the real socket of
a live mlaunch: malformed and deeply nested requests, a logs request for 100,000,000 lines of a
40 MB log, 30 ``mlaunch ctl`` at once. Nothing a client sends may stop or stall the run."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_for, wait_until

from mlaunch.parts.control_socket import MAX_LOG_LINES, Address

FLOOD_MB = 40
LAUNCH = f"""
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

TICK = 'import itertools, time\\nfor i in itertools.count():\\n    print("tick", i, flush=True); time.sleep(0.05)'
# {FLOOD_MB} MB of numbered lines into its log file only, then it waits.
FLOOD = (
    'import sys, time\\nout = sys.stdout.buffer\\n'
    'for i in range({FLOOD_MB} * 1024 * 1024 // 80):\\n    out.write(b"%079d\\\\n" % i)\\n'
    'out.flush(); time.sleep(600)'
)

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[sys.executable, '-c', TICK], name='talker', output='screen'),
        ExecuteProcess(cmd=[sys.executable, '-c', FLOOD], name='flood', output='log'),
    ])
"""


class Run:
    """A live mlaunch with a talker (a tick every 50 ms) and a flood's 40 MB log."""

    def __init__(self, tmp_path: Path) -> None:
        path = tmp_path / "hostile.launch.py"
        path.write_text(textwrap.dedent(LAUNCH))
        self.env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
        self.run = Running(mlaunch(str(path)), env=self.env)
        self.run.wait_for(r"\[talker-1\] tick 0")
        self.folder = Path(os.path.realpath(tmp_path / "logs" / "latest"))
        self.socket = str(self.folder / "control" / "ctl.sock")
        wait_for(lambda: os.path.exists(self.socket), 10, "the control socket")

    def raw(self, data: bytes, timeout: float = 10.0) -> list[dict[str, object]]:
        """Send ``data`` as it is; every answer line until the run closes the connection."""
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(timeout)
        with Address(self.socket) as address:
            sock.connect(address)
        with sock:
            sock.sendall(data)
            received = b""
            while chunk := sock.recv(65536):
                received += chunk
        return [json.loads(line) for line in received.splitlines()]

    def tick(self) -> int:
        done = run_mlaunch("ctl", "logs", "-n", "1", "talker", env=self.env)
        assert done.returncode == 0, done.stderr
        return int(done.stdout.split()[1])

    def still_running(self) -> None:
        """Both children run, the loop serves: the talker's log grows between two requests."""
        first = self.tick()
        assert wait_until(lambda: self.tick() > first, timeout=10)
        listed = self.raw(b'{"op": "list"}\n')[0]["processes"]
        assert isinstance(listed, list)
        assert [p["state"] for p in listed] == ["running", "running"], listed


@pytest.fixture
def live(tmp_path: Path) -> Iterator[Run]:
    run = Run(tmp_path)
    try:
        yield run
    finally:
        if run.run.proc.poll() is None:
            run.run.kill()


def test_malformed_and_deeply_nested_requests_are_answered_and_the_run_goes_on(
    live: Run,
) -> None:
    cases = {
        b"[" * 60_000 + b"\n": "the request is too long",
        b"[" * 4000 + b"\n": "the request is nested 4000 deep",
        b'{"op": "logs", "label": "talker", "lines": ' + b"[" * 50 + b"\n": "nested 51 deep",
        b"\xff\xfe{\n": "is not JSON",
        b'"list"\n': "is not a JSON object",
        b"{}\n": "unknown operation None",
        b'{"op": ["list"]}\n': "unknown operation ['list']",
        b'{"op": "stop", "label": {"a": 1}}\n': "stop needs a process label",
        b'{"op": "logs", "label": "talker", "lines": true}\n': "lines must be a whole number",
        b'{"op": "logs", "label": "talker", "lines": 1e400}\n': "lines must be a whole number",
        b'{"op": "logs", "label": "talker", "lines": ' + b"9" * 5000 + b"}\n": "too long",
        b"x" * 70_000: "the request is too long",
    }
    for data, error in cases.items():
        (answer,) = live.raw(data)
        assert answer["ok"] is False and error in str(answer["error"]), (data[:60], answer)
        assert answer["status"] == 2 or "label" in error or "operation" in error, answer
    # A number of 4,000 digits is a valid request: the most lines a request gets.
    (huge,) = live.raw(b'{"op": "logs", "label": "talker", "lines": ' + b"9" * 4000 + b"}\n")
    assert huge["ok"] is True and huge["limit"] == MAX_LOG_LINES
    live.still_running()
    assert "internal error" not in live.run.text and "SIGKILL" not in live.run.text


def test_logs_of_100000000_lines_of_a_40_mb_log_do_not_freeze_the_run(live: Run) -> None:
    log = live.folder / "flood-2.log"
    size = FLOOD_MB * 1024 * 1024 // 80 * 80
    assert wait_until(lambda: log.exists() and log.stat().st_size >= size, timeout=60)
    # The loop keeps serving while the big answer is made: a list asked at the same time.
    started = time.monotonic()
    done = subprocess.Popen(
        mlaunch("ctl", "logs", "-n", "100000000", "flood"),
        env=live.env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    listed = live.raw(b'{"op": "list"}\n')
    list_took = time.monotonic() - started
    out, err = done.communicate(timeout=60)
    took = time.monotonic() - started
    assert done.returncode == 0, err
    lines = out.splitlines()
    assert len(lines) == MAX_LOG_LINES
    last = FLOOD_MB * 1024 * 1024 // 80 - 1
    assert lines[-1] == f"{last:079d}" and lines[0] == f"{last - MAX_LOG_LINES + 1:079d}"
    assert f"only the last {MAX_LOG_LINES} lines" in err and "flood's log file" in err
    assert listed[0]["ok"] is True
    # Was 28 s of the loop's time (the tail re-read quadratically); now ~0.05 s of it.
    assert took < 10 and list_took < 5, (took, list_took)
    live.still_running()


def test_thirty_ctl_lists_at_once_all_succeed(live: Run) -> None:
    clients = [
        subprocess.Popen(
            mlaunch("ctl", "list"),
            env=live.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(30)
    ]
    results = [(c.wait(timeout=120), *c.communicate()) for c in clients]
    failed = [(code, err) for code, _, err in results if code != 0]
    assert not failed, failed
    assert all("talker-1" in out and "flood-2" in out for _, out, _ in results)


def test_thirty_clients_connecting_at_the_same_instant_all_get_answers(live: Run) -> None:
    """ctl's own client code in 30 threads released together: the connects arrive in the same
    millisecond, past a small listen queue (it was 8: 4-5 of 30 failed with EAGAIN)."""
    import threading

    from mlaunch.commands.ctl import ask, find_run

    barrier = threading.Barrier(30)
    results: list[object] = []

    def client() -> None:
        target = find_run(str(live.folder), live.env)
        barrier.wait(timeout=30)
        try:
            results.append(ask(target, {"op": "list"})["ok"])
        except Exception as e:  # the failure itself is what the test reports
            results.append(e)

    threads = [threading.Thread(target=client) for _ in range(30)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert results == [True] * 30, results
