"""Many processes under a small open-file limit: they all start (mlaunch raises its own soft
limit up to the hard one, and hands children the user's own), or the run is refused before the
first one. 500 processes under 1024 started ~336, then "internal error", exit 70; here the
limit is made small (``prlimit``) rather than starting hundreds.
"""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path

from procutil import Running, clean_env, mlaunch

MANY = """\
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(name=f'p{i}', output='screen',
        cmd=['sh', '-c', 'echo "limit $(ulimit -n)"; exec sleep 600']) for i in range(60)])
"""


def _launch(tmp_path: Path) -> str:
    path = tmp_path / "many.launch.py"
    path.write_text(MANY)
    return str(path)


def test_sixty_processes_under_a_limit_of_128_all_start(tmp_path: Path) -> None:
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "log"))
    run = Running(["prlimit", "--nofile=128:4096", *mlaunch(_launch(tmp_path))], env=env)
    try:
        for i in range(60):
            run.wait_for(rf"\[p{i}-{i + 1}\] limit 128$", 60)  # the user's own limit, not raised
        run.signal(signal.SIGINT)
        assert run.finish(60) == 130, run.text
        assert "Too many open files" not in run.text and "internal error" not in run.text
    finally:
        run.kill()


def test_processes_that_cannot_fit_the_hard_limit_are_refused_before_the_first(
    tmp_path: Path,
) -> None:
    done = subprocess.run(
        ["prlimit", "--nofile=128:128", *mlaunch(_launch(tmp_path))],
        capture_output=True,
        text=True,
        env=clean_env(ROS_LOG_DIR=str(tmp_path / "log")),
        timeout=60,
    )
    assert done.returncode == 2, done.stdout + done.stderr
    assert "60 processes need at least 212 open files (3 pipes each" in done.stderr
    assert "more than the hard limit of 128 (ulimit -Hn)" in done.stderr
    assert "process started" not in done.stdout + done.stderr
