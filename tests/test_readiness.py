"""Readiness for supervisors: systemd's notify protocol against a socket the test binds.

mlaunch FILE with NOTIFY_SOCKET set sends STATUS= while coming up, READY=1 once the launch is
ready by mlaunch test's rules (here: a node that joins the graph late), WATCHDOG=1 while healthy
(no more once a watched process died) and STOPPING=1 when it shuts down.
"""

from __future__ import annotations

import os
import signal
import socket
import textwrap
import threading
import time
from pathlib import Path

import pytest
from procutil import Running, clean_env, mlaunch, wait_for

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
rclpy.init(args=sys.argv)
node = rclpy.create_node("late")
open({marker!r}, "w").close()
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
        # The node joined the graph after its marker was written: READY=1 was not early.
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
