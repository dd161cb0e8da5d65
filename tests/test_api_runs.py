"""Behaviours of a run that actions written against upstream rely on (issue 25, gaps 8, 10)."""

from __future__ import annotations

from pathlib import Path

from procutil import clean_env, run_mlaunch

TIMER_OUTLIVES_SHUTDOWN = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, Shutdown, TimerAction

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[sys.executable, '-c', 'import time; time.sleep(30)']),
        TimerAction(period=0.2, actions=[Shutdown(reason='fast')]),
        TimerAction(period=0.8, actions=[LogInfo(msg='slow timer fired')],
                    cancel_on_shutdown=False),
        TimerAction(period=0.9, actions=[LogInfo(msg='cancelled timer fired')]),
    ])
"""


def test_a_timer_not_cancelled_on_shutdown_still_fires(tmp_path: Path) -> None:
    path = tmp_path / "t.launch.py"
    path.write_text(TIMER_OUTLIVES_SHUTDOWN)
    done = run_mlaunch(str(path), env=clean_env())
    out = done.stdout + done.stderr
    assert "slow timer fired" in out, out  # the shut-down launch waited for it, as launch does
    assert "cancelled timer fired" not in out


COMPLETIONS = """\
from launch import LaunchDescription
from launch.actions import GroupAction, LogInfo, RegisterEventHandler
from launch.event_handlers import OnExecutionComplete

def generate_launch_description():
    first = LogInfo(msg='first')
    grouped = LogInfo(msg='grouped')
    return LaunchDescription([
        RegisterEventHandler(OnExecutionComplete(
            target_action=first, on_completion=[LogInfo(msg='after first')])),
        RegisterEventHandler(OnExecutionComplete(
            target_action=grouped, on_completion=[LogInfo(msg='after grouped')])),
        first,
        GroupAction([grouped]),
        LogInfo(msg='last'),
    ])
"""


def test_every_action_completes_for_on_execution_complete(tmp_path: Path) -> None:
    path = tmp_path / "c.launch.py"
    path.write_text(COMPLETIONS)
    done = run_mlaunch(str(path), env=clean_env())
    said = [line.split("]: ", 1)[1] for line in done.stdout.splitlines() if "launch.user" in line]
    # launch's order (as recorded under ros2 launch): the visit first, then the events.
    assert said == ["first", "grouped", "last", "after first", "after grouped"], done.stderr
    printed = run_mlaunch(str(path), "--print", env=clean_env()).stdout
    assert "ExecutionComplete" not in printed  # implicit in the text plan


EXECUTE_LOCAL = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteLocal
from launch.descriptions import Executable

def generate_launch_description():
    return LaunchDescription([ExecuteLocal(
        process_description=Executable(
            cmd=[sys.executable, '-c', 'import os; print("got", os.environ["X"])'],
            additional_env={'X': 'hello'}),
        output='screen')])
"""


def test_execute_local_runs_its_executable_description(tmp_path: Path) -> None:
    path = tmp_path / "l.launch.py"
    path.write_text(EXECUTE_LOCAL)
    done = run_mlaunch(str(path), env=clean_env())
    assert done.returncode == 0, done.stderr
    assert "got hello" in done.stdout
