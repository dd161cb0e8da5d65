"""The launch-file locals inside timer and handler bodies (issue 25, gap 11): ThisLaunchFileDir
and $(dirname) are the folder of the file the body was written in, when the body fires."""

from __future__ import annotations

from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

PY_TIMER = """\
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, TimerAction
from launch.substitutions import ThisLaunchFileDir

def generate_launch_description():
    return LaunchDescription([TimerAction(period=0.05, actions=[
        LogInfo(msg=['timer in ', ThisLaunchFileDir()]),
        ExecuteProcess(cmd=['true'], cwd=ThisLaunchFileDir()),
    ])])
"""

XML_TIMER = """\
<launch>
  <timer period="0.05">
    <log message="timer in $(dirname)"/>
    <executable cmd="true" cwd="$(dirname)"/>
  </timer>
</launch>
"""

PY_HANDLER = """\
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.substitutions import ThisLaunchFileDir

def generate_launch_description():
    first = ExecuteProcess(cmd=['true'])
    return LaunchDescription([first, RegisterEventHandler(OnProcessExit(
        target_action=first, on_exit=[LogInfo(msg=['timer in ', ThisLaunchFileDir()])]))])
"""


@pytest.mark.parametrize(
    ("name", "text"),
    [("t.launch.py", PY_TIMER), ("t.launch.xml", XML_TIMER), ("h.launch.py", PY_HANDLER)],
)
def test_file_locals_resolve_when_the_body_fires(tmp_path: Path, name: str, text: str) -> None:
    folder = tmp_path / "pkg" / "launch"
    folder.mkdir(parents=True)
    (folder / name).write_text(text)
    # Started from elsewhere, so the current folder cannot stand in for the file's.
    done = run_mlaunch(str(folder / name), env=clean_env())
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert f"timer in {folder}" in out
    assert "outside of a launch file" not in out
