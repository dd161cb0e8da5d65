"""``mlaunch ctl`` talks only to a run of the caller's own: a socket another user planted in a
shared (1777) log folder, and a socket whose server runs as another uid, are refused before
anything is sent; an answer no run would send is a clear error (exit 1), never exit 70.

The servers are real processes on real sockets; the other user is ``nobody`` (uid 65534), taken
on by the server itself (os.setuid after its imports), which only root can do.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import Running, clean_env, mlaunch, run_mlaunch

NOBODY = 65534
as_root = pytest.mark.skipif(
    os.geteuid() != 0, reason="running a server as another uid (nobody) needs root"
)
# A control socket's server that answers every request with REPLY. ``plant``: it becomes nobody
# first and makes the run's folders itself (another user's planted socket); ``drop``: it binds as
# the caller and listens as nobody (SO_PEERCRED names nobody); ``same``: it stays the caller.
SERVER = textwrap.dedent(
    """
    import json, os, socket, sys
    path, mode, reply = sys.argv[1], sys.argv[2], sys.argv[3].encode()
    if mode == "plant":
        os.setgroups([]); os.setgid(65534); os.setuid(65534)
        os.makedirs(os.path.dirname(path), mode=0o700)
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    os.chdir(os.path.dirname(path))  # a test's folder is longer than AF_UNIX takes
    server.bind(os.path.basename(path))
    if mode == "drop":
        os.setgroups([]); os.setgid(65534); os.setuid(65534)
    server.listen(8)
    print("listening", flush=True)
    while True:
        conn, _ = server.accept()
        data = conn.recv(65536)
        print("got", repr(data), flush=True)
        if data:  # not a probe that only looked whether anyone accepts
            conn.sendall(reply.replace(b"PID", str(os.getpid()).encode()) + b"\\n")
        conn.close()
    """
)
STOPPED = (
    '{"ok": true, "process": {"label": "talker-1", "state": "stopped", "outcome":'
    ' "stopped by the user"}, "run": {"pid": PID, "run_id": "PID-0000abcd", "log_dir": "x"}}'
)
RUN_NAME = "2099-01-01-00-00-00-000000-host-4242"


@pytest.fixture
def shared() -> Iterator[Path]:
    """A log base like a shared ROS_LOG_DIR: 1777, outside root's private temporary folders."""
    base = Path(tempfile.mkdtemp(prefix="mlaunch-shared-", dir="/tmp"))
    base.chmod(0o1777)
    try:
        yield base
    finally:
        shutil.rmtree(base, ignore_errors=True)


def serve(path: Path, mode: str, reply: str = STOPPED) -> Running:
    server = Running([sys.executable, "-c", SERVER, str(path), mode, reply], env=clean_env())
    server.wait_for("listening")
    return server


@as_root
def test_a_planted_socket_of_another_user_is_never_asked(shared: Path) -> None:
    planted = shared / RUN_NAME / "control" / "ctl.sock"
    env = clean_env(ROS_LOG_DIR=str(shared))
    server = serve(planted, "plant")
    try:
        assert os.stat(planted).st_uid == NOBODY
        named = run_mlaunch("ctl", RUN_NAME, "stop", "talker", env=env)
        assert named.returncode == 1, named.stdout + named.stderr
        assert f"the control socket {planted} belongs to uid 65534 (nobody)" in named.stderr
        assert "not a run of yours: nothing was sent to it" in named.stderr
        newest = run_mlaunch("ctl", "stop", "talker", env=env)
        assert newest.returncode == 1, newest.stdout + newest.stderr
        assert "1 not yours skipped" in newest.stderr and "uid 65534 (nobody)" in newest.stderr
        assert "got" not in server.text  # nothing connected to it
    finally:
        server.kill()


@as_root
def test_the_real_run_is_found_past_a_planted_newer_one(shared: Path, tmp_path: Path) -> None:
    """The issue's case: root's ``ctl stop talker`` reached the planted socket, said "stopped"
    and exit 0, and the real run was never asked. Now the planted one is skipped."""
    launch = tmp_path / "one.launch.py"
    launch.write_text(
        "import sys\nfrom launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([ExecuteProcess(name='talker', output='screen',\n"
        "        cmd=[sys.executable, '-c', 'import time; print(\"up\", flush=True);"
        " time.sleep(600)'])])\n"
    )
    env = clean_env(ROS_LOG_DIR=str(shared))
    run = Running(mlaunch(str(launch)), env=env)
    server = serve(shared / RUN_NAME / "control" / "ctl.sock", "plant")
    try:
        run.wait_for(r"\[talker-1\] up")
        # Without 'latest', ctl goes by the folders' names, newest (the planted one) first.
        (shared / "latest").unlink()
        done = run_mlaunch("ctl", "stop", "talker", env=env)
        assert done.returncode == 0, done.stdout + done.stderr
        assert done.stdout == "talker-1: stopped by the user\n"
        run.wait_for(r"\[talker-1\]: process stopped by the user")
        assert "got" not in server.text
    finally:
        server.kill()
        run.kill()


@as_root
def test_a_server_of_another_uid_behind_an_own_socket_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "logs" / RUN_NAME / "control"
    folder.mkdir(parents=True, mode=0o700)
    server = serve(folder / "ctl.sock", "drop")
    try:
        env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
        done = run_mlaunch("ctl", RUN_NAME, "stop", "talker", env=env)
        assert done.returncode == 1, done.stdout + done.stderr
        assert (
            "is served by pid" in done.stderr and "of uid 65534 (nobody), not by you" in done.stderr
        )
        server.wait_for("got b''")  # it was connected to, and sent nothing
    finally:
        server.kill()


@pytest.mark.parametrize(
    ("reply", "said"),
    [
        ("hello", "answered something no mlaunch run sends (not JSON"),
        ("[1, 2]", "(not a JSON object): '[1, 2]'"),
        ('{"accepted": true, "wait": "forever"}', "its wait is not a number of seconds"),
        ('{"status": 0}', "(it has no 'ok')"),
        ('{"ok": true, "run": {"pid": 1}}', "but its answer names pid 1: not an answer to trust"),
    ],
)
def test_an_unexpected_answer_is_a_clear_error(tmp_path: Path, reply: str, said: str) -> None:
    folder = tmp_path / "logs" / RUN_NAME / "control"
    folder.mkdir(parents=True, mode=0o700)
    server = serve(folder / "ctl.sock", "same", reply)
    try:
        env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
        done = run_mlaunch("ctl", "stop", "talker", env=env)
        assert done.returncode == 1, done.stdout + done.stderr
        assert said in done.stderr, done.stderr
        assert "internal error" not in done.stderr
    finally:
        server.kill()
