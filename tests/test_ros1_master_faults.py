"""A native ROS 1 run (--ros1) against a ROS_MASTER_URI it cannot use: one line and a status,
never an internal error or a wait without end (issue 38, item 13)."""

from __future__ import annotations

import socket
import time
from pathlib import Path

import pytest
from ports import free_port
from procutil import clean_env, run_mlaunch

LAUNCH = '<launch>\n  <param name="x" value="1"/>\n</launch>\n'


@pytest.fixture
def launch(tmp_path: Path) -> Path:
    path = tmp_path / "one.launch"
    path.write_text(LAUNCH)
    return path


@pytest.mark.parametrize(
    ("uri", "why"),
    [
        ("localhost:11311", ""),  # before: OSError: unsupported XML-RPC protocol, exit 70
        ("ftp://localhost:11311/", ""),
        ("http://:11311/", ""),
        ("http://localhost:abc/", "could not be cast to integer"),  # before: InvalidURL, 70
        ("http://localhost:99999/", "out of range"),
    ],
)
def test_a_malformed_master_uri_is_one_usage_line(
    launch: Path, tmp_path: Path, uri: str, why: str
) -> None:
    env = clean_env(ROS_MASTER_URI=uri, ROS_LOG_DIR=str(tmp_path / "log"))
    done = run_mlaunch("--ros1", str(launch), env=env)
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"mlaunch: error: ROS_MASTER_URI={uri!r} is not a ROS master's"), line
    assert why in line and "http://HOST:PORT/" in line, line


def test_a_master_port_held_by_something_else_is_said_at_once(launch: Path, tmp_path: Path) -> None:
    # Something that accepts connections and never answers: mlaunch's rosmaster could not bind
    # the port and waited without end, and the parameter loader waited 30 s for it.
    port = free_port()
    holder = socket.socket()
    holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    holder.bind(("127.0.0.1", port))
    holder.listen(16)
    try:
        env = clean_env(ROS_MASTER_URI=f"http://localhost:{port}/", ROS_LOG_DIR=str(tmp_path))
        start = time.monotonic()
        done = run_mlaunch("--ros1", str(launch), env=env, timeout=60)
        took = time.monotonic() - start
    finally:
        holder.close()
    assert done.returncode == 2, done.stdout + done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert f"port {port} is held by a program that is not a ROS master" in line, line
    assert "master-1" not in done.stdout  # nothing started
    assert took < 25, took  # the loader's own wait is 30 s
