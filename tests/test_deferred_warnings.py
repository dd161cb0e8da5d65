"""The "resolved when it fires" warning (issue 27, item 18): launch_testing runs printed it for
the runner's own bookkeeping handlers, located at ``.venv/bin/mlaunch:6`` and naming nothing.
It is said only for the user's timers and handlers, at their line, naming what they hold."""

from __future__ import annotations

import re
from pathlib import Path

from procutil import clean_env, run_mlaunch

# 'mode' is declared after the timer that reads it: the timer's LogInfo sees 'fast' when it
# fires (launch's rule), not the unset value where it was written; that one warning is due.
TEST_FILE = """\
import sys, unittest
import launch, launch_testing, launch_testing.actions
from launch.actions import DeclareLaunchArgument, ExecuteProcess, TimerAction, LogInfo
from launch.substitutions import LaunchConfiguration

def generate_test_description():
    proc = ExecuteProcess(cmd=[sys.executable, '-c', 'import time; print("hi", flush=True); time.sleep(1)'],
                          name='dut')
    return launch.LaunchDescription([
        DeclareLaunchArgument('speed', default_value='1'),
        TimerAction(period=0.2, actions=[LogInfo(msg=LaunchConfiguration('mode'))]),
        DeclareLaunchArgument('mode', default_value='fast'),
        proc,
        launch_testing.actions.ReadyToTest(),
    ]), {'dut': proc}

class TestIt(unittest.TestCase):
    def test_started(self, proc_info, dut):
        proc_info.assertWaitForShutdown(process=dut, timeout=10)  # after the timer fired
"""


def test_launch_testing_warns_only_for_the_users_timer_at_its_line(tmp_path: Path) -> None:
    path = tmp_path / "late.test.py"
    path.write_text(TEST_FILE)
    done = run_mlaunch("test", str(path), env=clean_env(), timeout=120)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    warnings = re.findall(r"\[WARNING\] \[launch\]: (.*resolved when it fires.*)", out)
    assert len(warnings) == 1, warnings
    assert warnings[0].startswith(
        f"{path}:11: LogInfo: resolved when it fires, as ros2 launch does, and launch"
        " configuration 'mode' is unset where written, 'fast' when it fires"
    ), warnings
    assert "bin/mlaunch:" not in out
