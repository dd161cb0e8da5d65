"""Faults at the viewer stand-in's page server: browsers that reset their connections.

A reload or a cancelled poll resets the connection while the server answers; socketserver used
to print a 20-line traceback into the launch output for each. The resets are real here (TCP RST
through SO_LINGER 0), and the server's stderr is the test's.
"""

from __future__ import annotations

import json
import socket
import struct
import time
import urllib.request
from collections.abc import Iterator

import pytest
from procutil import wait_until

from mlaunch.standins.viewer import DisplayConfig, PageServer, ViewerState, serve


def reset_connection(port: int) -> None:
    """A browser that asks and goes away at once: the server's answer meets a TCP reset."""
    s = socket.create_connection(("127.0.0.1", port))
    s.sendall(b"GET /state.json HTTP/1.1\r\nHost: viewer\r\n\r\n")
    s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    s.close()


@pytest.fixture
def server() -> Iterator[PageServer]:
    page_server = serve(ViewerState(DisplayConfig()), 0, time.monotonic)
    yield page_server
    page_server.shutdown()
    page_server.server_close()


def test_browser_resets_print_nothing_and_the_page_still_answers(
    server: PageServer, capfd: pytest.CaptureFixture[str]
) -> None:
    port = server.server_address[1]
    for _ in range(20):
        reset_connection(port)
    assert wait_until(lambda: server.gone >= 1), "no reset reached the server"
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/state.json", timeout=10) as reply:
        assert "robot" in json.loads(reply.read())
    err = capfd.readouterr().err
    assert "Traceback" not in err and "ConnectionResetError" not in err, err
    print(f"{server.gone} of 20 resets met the server mid-answer, silently")


def test_another_request_failure_is_one_line(
    server: PageServer, capfd: pytest.CaptureFixture[str]
) -> None:
    try:
        raise ValueError("bad state")
    except ValueError:
        server.handle_error(None, ("127.0.0.1", 4242))
    err = capfd.readouterr().err
    assert err == "viewer: a request from 127.0.0.1:4242 failed: ValueError: bad state\n"
