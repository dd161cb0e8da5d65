"""Readiness for supervisors: systemd's notify protocol against a socket the test binds.

mlaunch FILE with NOTIFY_SOCKET set sends STATUS= while coming up, READY=1 once the launch is
ready by mlaunch test's rules (here: a node that joins the graph late), WATCHDOG=1 while healthy
(no more once a watched process died) and STOPPING=1 when it shuts down.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import textwrap
import threading
import time
from pathlib import Path

import pytest
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_for

from mlaunch.parts.sd_notify import Notifier, watchdog_interval_usec


class Listener:
    """A datagram socket a test binds, as systemd's; keeps (time, message) pairs."""

    def __init__(self, address: str) -> None:
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.sock.bind(b"\0" + address[1:].encode() if address.startswith("@") else address)
        self.sock.settimeout(0.2)
        self.messages: list[tuple[float, str]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.sock.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                return
            self.messages.append((time.monotonic(), data.decode()))

    def first(self, key: str) -> tuple[float, str] | None:
        return next((m for m in list(self.messages) if key in m[1].splitlines()), None)

    def with_prefix(self, prefix: str) -> list[tuple[float, str]]:
        return [
            m for m in list(self.messages) if any(x.startswith(prefix) for x in m[1].splitlines())
        ]

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)
        self.sock.close()


def test_notifier_sends_to_path_and_abstract_sockets(tmp_path: Path) -> None:
    for address in (str(tmp_path / "notify"), f"@mlaunch-test-{os.getpid()}-{id(tmp_path)}"):
        listener = Listener(address)
        try:
            notifier = Notifier.from_environ({"NOTIFY_SOCKET": address})
            assert notifier is not None
            assert notifier.ready("up\nand running")
            assert notifier.watchdog()
            got = listener.messages
            wait_for(lambda: len(got) == 2, 5, "two datagrams")  # noqa: B023 (this listener's)
            ready = listener.messages[0][1].splitlines()
            assert ready[:2] == ["READY=1", "STATUS=up and running"]  # one line per field
            assert listener.messages[1][1] == "WATCHDOG=1"
            notifier.close()
        finally:
            listener.close()


def test_bad_or_gone_notify_socket_is_said_not_raised(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="NOTIFY_SOCKET='relative/path'"):
        Notifier.from_environ({"NOTIFY_SOCKET": "relative/path"})
    assert Notifier.from_environ({}) is None
    gone = Notifier(str(tmp_path / "nobody-listens"))
    assert not gone.status("x")
    assert "nobody-listens" in gone.error
    env = {"WATCHDOG_USEC": "500000", "WATCHDOG_PID": str(os.getpid())}
    assert watchdog_interval_usec(env) == 500000
    assert watchdog_interval_usec({**env, "WATCHDOG_PID": "1"}) == 0  # for another process


LATE_NODE = """\
import sys, time
time.sleep(float(sys.argv[1]))
import rclpy
open({marker!r}, "w").close()  # about to join the graph
rclpy.init(args=sys.argv)
node = rclpy.create_node("late")
try:
    rclpy.spin(node)
except BaseException:
    pass
"""

WAITER = """\
import os, sys, time
while not os.path.exists(sys.argv[1]):
    time.sleep(0.05)
sys.exit(3)
"""

LAUNCH = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess
from launch_ros.actions import Node

def generate_launch_description():
    return LaunchDescription([
        Node(executable=sys.executable, arguments=[{late!r}, "1.5"], name="late",
             exec_name="late"),
        ExecuteProcess(cmd=[sys.executable, {waiter!r}, {die!r}], name="worker"),
    ])
"""


def test_ready_only_once_the_node_is_in_the_graph_and_watchdog_stops_on_a_death(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    marker, die = tmp_path / "joined", tmp_path / "die"
    late, waiter = tmp_path / "late.py", tmp_path / "waiter.py"
    late.write_text(LATE_NODE.format(marker=str(marker)))
    waiter.write_text(WAITER)
    launch = tmp_path / "fleet.launch.py"
    launch.write_text(
        textwrap.dedent(LAUNCH).format(late=str(late), waiter=str(waiter), die=str(die))
    )
    address = str(tmp_path / "notify.sock")
    listener = Listener(address)
    env = clean_env(
        **ros_env,
        NOTIFY_SOCKET=address,
        WATCHDOG_USEC="200000",
        ROS_LOG_DIR=str(tmp_path / "log"),
    )
    run = Running(mlaunch(str(launch)), env=env)
    try:
        ready = wait_for(lambda: listener.first("READY=1"), 60, "READY=1")
        # The node joins the graph after its marker is written: READY=1 was not early.
        assert marker.exists(), listener.messages
        starting = [m for m in listener.with_prefix("STATUS=starting") if m[0] <= ready[0]]
        assert starting, listener.messages
        assert any("node /late" in m[1] for m in starting), starting
        wait_for(lambda: listener.with_prefix("WATCHDOG=1"), 10, "a WATCHDOG=1 after ready")
        die.touch()  # the worker exits with status 3: the launch is no longer healthy
        failed = wait_for(lambda: listener.with_prefix("STATUS=not ready"), 20, "not ready")
        assert "worker" in failed[0][1], failed
        # Pings are every 0.1 s while healthy: none for ten periods after the failure.
        time.sleep(1.0)  # a span in which a ping would have come, not a synchronisation
        late_pings = [m for m in listener.with_prefix("WATCHDOG=1") if m[0] > failed[0][0]]
        assert not late_pings, listener.messages
        run.signal(signal.SIGINT)
        run.finish(30)
        stopping = wait_for(lambda: listener.first("STOPPING=1"), 5, "STOPPING=1")
        assert stopping[0] > failed[0][0]
    finally:
        if run.proc.poll() is None:
            run.kill()
        listener.close()


GHOST = """\
import sys
from launch import LaunchDescription
from launch_ros.actions import Node

def generate_launch_description():
    return LaunchDescription([
        Node(executable=sys.executable, arguments=[{late!r}, "1.0"], name="late",
             exec_name="late"),
        Node(executable=sys.executable, arguments=["-c", "import time; time.sleep(600)"],
             name="ghost", exec_name="ghost"),
    ])
"""


def wait_ready(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return run_mlaunch("ctl", "wait-ready", *args, env=env, timeout=120)


def test_wait_ready_exit_status_and_what_is_missing(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    marker = tmp_path / "joined"
    late = tmp_path / "late.py"
    late.write_text(LATE_NODE.format(marker=str(marker)))
    env = clean_env(**ros_env, ROS_LOG_DIR=str(tmp_path / "log"))
    nobody = wait_ready(env, "4242424", "--timeout", "0.5")
    assert nobody.returncode == 2, nobody.stderr
    assert "no run pid 4242424" in nobody.stderr

    launch = tmp_path / "ghost.launch.py"
    launch.write_text(GHOST.format(late=str(late)))
    run = Running(mlaunch(str(launch)), env=env)
    try:
        # Asked at once: the run is waited for, then its checks; /ghost never joins the graph.
        done = wait_ready(env, str(run.proc.pid), "--timeout", "6", "--json")
        assert done.returncode == 1, done.stdout + done.stderr
        answer = json.loads(done.stdout)
        assert answer["ok"] is False and answer["status"] == 1 and answer["ready"] is False
        states = {(c["check"], c["target"]): c["state"] for c in answer["checks"]}
        assert states[("node", "/ghost")] == "pending", answer
        processes = [c for c in answer["checks"] if c["check"] == "process"]
        assert [c["state"] for c in processes] == ["met", "met"], answer
        text = wait_ready(env, str(run.proc.pid), "--timeout", "0.5")
        assert text.returncode == 1
        assert "pending: node /ghost is in the ROS graph" in text.stderr, text.stderr
    finally:
        run.signal(signal.SIGINT)
        run.finish(30)


LATE_ONLY = GHOST.split('        Node(executable=sys.executable, arguments=["-c"')[0] + "    ])\n"

DIES = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=[sys.executable, "-c", "exit(3)"], name="dies")])
"""


def test_wait_ready_passes_once_ready_and_fails_fast_on_a_launch_that_dies(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    marker = tmp_path / "joined"
    late = tmp_path / "late.py"
    late.write_text(LATE_NODE.format(marker=str(marker)))
    env = clean_env(**ros_env, ROS_LOG_DIR=str(tmp_path / "log"))
    launch = tmp_path / "late.launch.py"
    launch.write_text(LATE_ONLY.format(late=str(late)))
    run = Running(mlaunch(str(launch)), env=env)
    try:
        done = wait_ready(env, str(run.proc.pid), "--timeout", "60")
        assert done.returncode == 0, done.stdout + done.stderr
        assert marker.exists()  # not ready before the late node was up
        assert done.stdout.startswith("ready: 2 checks met"), done.stdout
    finally:
        run.signal(signal.SIGINT)
        run.finish(30)
    dies = tmp_path / "dies.launch.py"
    dies.write_text(DIES)
    run = Running(mlaunch(str(dies)), env=env)
    try:
        started = time.monotonic()
        done = wait_ready(env, str(run.proc.pid), "--timeout", "60")
        assert done.returncode == 1, done.stdout + done.stderr
        assert time.monotonic() - started < 30  # not the whole timeout
        assert "ended before it was ready" in done.stderr, done.stderr
    finally:
        run.finish(30)
