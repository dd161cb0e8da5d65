"""``mlaunch ctl`` talks only to a run of the caller's own: a socket another user planted in a
shared (1777) log folder, and a socket whose server runs as another uid, are refused before
anything is sent; an answer no run would send is a clear error (exit 1), never exit 70.

The servers are real processes on real sockets; the other user is ``nobody`` (uid 65534), taken
on by the server itself (os.setuid after its imports), which only root can do.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_until

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
        folder = planted.parent.parent  # found before the socket: the run folder is not root's
        assert f"the run folder {folder} belongs to uid 65534 (nobody)" in named.stderr
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


def _as_nobody(*argv: str) -> None:
    """Run ``argv`` as nobody (the other user of a shared machine)."""
    done = subprocess.run(
        ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", *argv],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 0, done.stderr


def _sleeper(tmp_path: Path, name: str) -> Path:
    launch = tmp_path / f"{name}.launch.py"
    launch.write_text(
        "import sys\nfrom launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        f"    return LaunchDescription([ExecuteProcess(name='{name}', output='screen',\n"
        "        cmd=[sys.executable, '-c', 'import time; print(\"up\", flush=True);"
        " time.sleep(600)'])])\n"
    )
    return launch


def _run_folder(shared: Path, pid: int) -> Path:
    found = [p for p in shared.iterdir() if p.name.endswith(f"-{pid}")]
    assert len(found) == 1, list(shared.iterdir())
    return found[0]


@as_root
def test_a_planted_where_file_never_leads_to_another_run(shared: Path, tmp_path: Path) -> None:
    """nobody's run folder whose ``control/where`` names root's real run's socket: root's
    ``ctl FOLDER stop talker`` stopped the talker of that other run, exit 0."""
    env = clean_env(ROS_LOG_DIR=str(shared))
    run = Running(mlaunch(str(_sleeper(tmp_path, "talker"))), env=env)
    try:
        run.wait_for(r"\[talker-1\] up")
        real = _run_folder(shared, run.proc.pid) / "control" / "ctl.sock"
        assert wait_until(real.exists, 30)
        planted = shared / RUN_NAME
        _as_nobody("mkdir", "-p", "-m", "700", str(planted / "control"))
        _as_nobody("sh", "-c", f"echo {real} > {planted / 'control' / 'where'}")
        for how in ([RUN_NAME], [str(planted)]):
            done = run_mlaunch("ctl", *how, "stop", "talker", env=env)
            assert done.returncode == 1, done.stdout + done.stderr
            assert f"the run folder {planted} belongs to uid 65534 (nobody)" in done.stderr
            assert "nothing was sent to it" in done.stderr
        # root's own folder with nobody's where file in a control folder of root's: refused too.
        own = shared / "2099-01-02-00-00-00-000000-host-4343" / "control"
        own.mkdir(parents=True, mode=0o700)
        (own / "where").write_text(f"{real}\n")
        os.chown(own / "where", NOBODY, NOBODY)
        done = run_mlaunch("ctl", own.parent.name, "stop", "talker", env=env)
        assert done.returncode == 1, done.stdout + done.stderr
        assert f"{own / 'where'} is a file of uid 65534 (nobody)" in done.stderr
        newest = run_mlaunch("ctl", "list", env=env)  # the real run, past both
        assert newest.returncode == 0, newest.stdout + newest.stderr
        assert "talker-1  running" in newest.stdout
        assert "stopped by the user" not in run.text
    finally:
        run.kill()


@as_root
def test_a_planted_latest_folder_is_not_followed(shared: Path, tmp_path: Path) -> None:
    """nobody makes ``latest`` a folder before root's first run, then links its ``control`` to
    the older of root's two runs: ``ctl stop talker`` (the newest run) and ``ctl latest ...``
    reached the older run instead."""
    env = clean_env(ROS_LOG_DIR=str(shared))
    _as_nobody("mkdir", "-m", "755", str(shared / "latest"))
    older = Running(mlaunch(str(_sleeper(tmp_path, "talker"))), env=env)
    newer = None
    try:
        older.wait_for(r"\[talker-1\] up")
        control = _run_folder(shared, older.proc.pid) / "control"
        assert wait_until((control / "ctl.sock").exists, 30)
        _as_nobody("ln", "-s", str(control), str(shared / "latest" / "control"))
        newer = Running(mlaunch(str(_sleeper(tmp_path, "talker"))), env=env)
        newer.wait_for(r"\[talker-1\] up")
        newest = _run_folder(shared, newer.proc.pid) / "control" / "ctl.sock"
        assert wait_until(newest.exists, 30)
        done = run_mlaunch("ctl", "stop", "talker", env=env)
        assert done.returncode == 0, done.stdout + done.stderr
        newer.wait_for(r"\[talker-1\]: process stopped by the user")
        named = run_mlaunch("ctl", "latest", "stop", "talker", env=env)
        assert named.returncode == 1, named.stdout + named.stderr
        assert f"{shared / 'latest'} is not the symlink a run makes but a folder" in named.stderr
        assert "stopped by the user" not in older.text
    finally:
        older.kill()
        if newer is not None:
            newer.kill()
