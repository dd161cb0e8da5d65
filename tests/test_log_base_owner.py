"""A log base another user can change is refused before anything starts: with ROS_LOG_DIR made
by nobody, nobody could swap root's fresh run folder for a link to root's own files, and
mlaunch chmodded a root folder to 700 and appended a child's output to a root-owned file.
A shared sticky (1777) base, like /tmp, still works: each user's entries stay their own.

The other user is ``nobody`` (setpriv), which only root can play.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

LAUNCH = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(name='hello', output='screen',
        cmd=[sys.executable, '-c', 'print("hello from the child")'])])
"""
as_root = pytest.mark.skipif(os.geteuid() != 0, reason="playing another user (nobody) needs root")


@pytest.fixture
def shared(tmp_path: Path) -> Iterator[Path]:
    """A folder every user can reach (tmp_path's parents are root's 0700)."""
    base = Path("/tmp") / f"mlaunch-logs-{os.getpid()}-{tmp_path.name}"
    base.mkdir()
    base.chmod(0o1777)
    yield base
    subprocess.run(["rm", "-rf", str(base)], check=False)


def _run(tmp_path: Path, log: Path) -> tuple[int, str]:
    launch = tmp_path / "hello.launch.py"
    launch.write_text(LAUNCH)
    done = run_mlaunch(str(launch), env=clean_env(ROS_LOG_DIR=str(log)))
    return done.returncode, done.stdout + done.stderr


@as_root
def test_a_log_base_another_user_owns_is_refused(tmp_path: Path, shared: Path) -> None:
    theirs = shared / "log"
    subprocess.run(
        ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", "mkdir", str(theirs)],
        check=True,
        timeout=30,
    )
    code, out = _run(tmp_path, theirs)
    assert code == 2, out
    assert f"the log folder {theirs} is not safe for this run's logs: {theirs} belongs to" in out
    assert "uid 65534 (nobody), not to you" in out
    assert "set ROS_LOG_DIR to a folder of your own" in out
    assert "hello from the child" not in out and list(theirs.iterdir()) == []


def test_a_log_base_others_can_write_is_refused(tmp_path: Path) -> None:
    open_to_all = tmp_path / "log"
    open_to_all.mkdir()
    open_to_all.chmod(0o777)  # no sticky bit: anyone may rename the run's folder
    code, out = _run(tmp_path, open_to_all)
    assert code == 2, out
    assert f"{open_to_all} has mode 777: others can write into it" in out
    assert list(open_to_all.iterdir()) == []


def test_a_shared_sticky_log_base_still_works(tmp_path: Path, shared: Path) -> None:
    code, out = _run(tmp_path, shared)
    assert code == 0, out
    assert "hello from the child" in out
    (log,) = [p for p in shared.glob("*/hello-1.log") if p.parent.name != "latest"]
    assert log.read_text() == "hello from the child\n"
