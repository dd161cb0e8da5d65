"""The viewer's page server against other web pages and idle clients, and driving the robot from
the page (issue 27, items 12 and 16). Real sockets and a real viewer process; no mocks."""

from __future__ import annotations

import json
import socket
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import wait_for
from test_viewer import RVIZ_CONFIG, Child

from mlaunch.standins.viewer import DisplayConfig, PageServer, ViewerState, serve
from mlaunch.standins.viewer_http import IDLE_TIMEOUT, MAX_LINEAR


@pytest.fixture
def driven() -> Iterator[tuple[PageServer, list[tuple[float, float]]]]:
    commands: list[tuple[float, float]] = []
    server = serve(
        ViewerState(DisplayConfig()), 0, time.monotonic, lambda v, w: commands.append((v, w))
    )
    yield server, commands
    server.shutdown()
    server.server_close()


def ask(port: int, request: bytes) -> tuple[int, bytes]:
    """Send a raw HTTP request (as any client may write it); the status and body."""
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(request)
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    return int(head.split(b" ", 2)[1]), body


def get(port: int, host: str | None) -> tuple[int, bytes]:
    header = b"" if host is None else f"Host: {host}\r\n".encode()
    return ask(port, b"GET /state.json HTTP/1.1\r\n" + header + b"Connection: close\r\n\r\n")


def post(
    port: int, body: bytes, *, origin: str | None, kind: str = "application/json"
) -> tuple[int, bytes]:
    lines = [
        "POST /cmd_vel HTTP/1.1",
        f"Host: 127.0.0.1:{port}",
        f"Content-Type: {kind}",
        f"Content-Length: {len(body)}",
        "Connection: close",
        *([f"Origin: {origin}"] if origin is not None else []),
    ]
    return ask(port, ("\r\n".join(lines) + "\r\n\r\n").encode() + body)


def test_only_requests_addressed_to_127_0_0_1_or_localhost_are_answered(
    driven: tuple[PageServer, list[tuple[float, float]]],
) -> None:
    port = driven[0].server_address[1]
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", "LOCALHOST", "127.0.0.1"):
        status, body = get(port, host)
        assert status == 200 and "robot" in json.loads(body), host
    # DNS rebinding: a page of evil.example whose name now resolves to 127.0.0.1
    for other in (f"evil.example:{port}", "evil.example", f"127.0.0.1:{port + 1}", "", None):
        status, body = get(port, other)
        assert status == 421 and b"robot" not in body, (other, status)


def test_an_idle_connection_is_closed(
    driven: tuple[PageServer, list[tuple[float, float]]],
) -> None:
    port = driven[0].server_address[1]
    with socket.create_connection(("127.0.0.1", port)) as s:
        s.settimeout(IDLE_TIMEOUT + 10)
        start = time.monotonic()
        assert s.recv(1) == b""  # before: never closed (one thread each, forever)
        assert IDLE_TIMEOUT - 0.5 < time.monotonic() - start < IDLE_TIMEOUT + 5
    status, _ = get(port, f"127.0.0.1:{port}")
    assert status == 200


def test_the_page_drives_and_nobody_else_does(
    driven: tuple[PageServer, list[tuple[float, float]]],
) -> None:
    server, commands = driven
    port = server.server_address[1]
    page = f"http://127.0.0.1:{port}"
    assert post(port, b'{"linear": 0.5, "angular": -1.0}', origin=page)[0] == 204
    assert post(port, b'{"linear": 99, "angular": 0}', origin=f"http://localhost:{port}")[0] == 204
    assert commands == [(0.5, -1.0), (MAX_LINEAR, 0.0)]  # clamped
    refused = [
        post(port, b'{"linear": 1, "angular": 0}', origin=None),  # curl, a script
        post(port, b'{"linear": 1, "angular": 0}', origin="http://evil.example"),
        post(port, b'{"linear": 1, "angular": 0}', origin=f"http://127.0.0.1:{port + 1}"),
        post(port, b"linear=1&angular=0", origin=page, kind="application/x-www-form-urlencoded"),
        post(port, b'{"linear": "NaN", "angular": 0}', origin=page),
        post(port, b"[", origin=page),
    ]
    assert [status for status, _ in refused] == [403, 403, 403, 400, 400, 400]
    assert len(commands) == 2


SUBSCRIBER = """
import sys, rclpy
from geometry_msgs.msg import Twist
rclpy.init()
node = rclpy.create_node("cmd_vel_listener")
def seen(msg):
    print(f"twist {msg.linear.x} {msg.angular.z}", flush=True)
node.create_subscription(Twist, "/cmd_vel", seen, 10)
print("listening", flush=True)
rclpy.spin(node)
"""


@requires_rclpy
@pytest.mark.timeout(60)
def test_a_key_press_reaches_cmd_vel_through_the_real_viewer(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    config = tmp_path / "view.rviz"
    config.write_text(RVIZ_CONFIG)
    env = {**ros_env, "MLAUNCH_VIEWER_PORT": "0"}
    listener = Child([sys.executable, "-c", SUBSCRIBER], env, tmp_path, "listener")
    viewer = Child(
        [sys.executable, "-m", "mlaunch.standins.viewer", "-d", str(config)],
        env,
        tmp_path,
        "viewer",
    )
    try:
        line = wait_for(
            lambda: next(
                (ln for ln in viewer.stdout().splitlines() if ln.startswith("viewer: open")), None
            ),
            20,
            "the viewer's 'open' line",
        )
        url = line.split()[-1].rstrip("/")
        wait_for(lambda: "listening" in listener.stdout() or None, 20, "the listener")

        def sent() -> bool | None:
            request = urllib.request.Request(
                f"{url}/cmd_vel",
                data=b'{"linear": 0.5, "angular": 1.2}',
                headers={"Content-Type": "application/json", "Origin": url},
            )  # what the page's fetch sends when an arrow key is held
            with urllib.request.urlopen(request, timeout=5) as reply:
                assert reply.status == 204
            return "twist 0.5 1.2" in listener.stdout() or None

        wait_for(sent, 20, "a Twist on /cmd_vel")  # sent again until discovery has matched
    finally:
        viewer.stop()
        listener.stop()
