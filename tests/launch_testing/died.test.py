"""The only process ends at once and nothing keeps the launch alive: the active test never
finishes, so every test of the run fails with 'Launch stopped before the active tests finished'."""

import os
import sys
import unittest

import launch
import launch.actions
import launch_testing
import launch_testing.actions

CHATTER = os.path.join(os.path.dirname(__file__), "chatter.py")


def generate_test_description():
    return launch.LaunchDescription(
        [
            launch.actions.ExecuteProcess(
                cmd=[sys.executable, CHATTER, "--count", "0", "--exit", "1"]
            ),
            launch_testing.actions.ReadyToTest(),
        ]
    )


class TestWaitsTooLong(unittest.TestCase):
    def test_waits(self, proc_output):
        proc_output.assertWaitFor("never printed", timeout=60, stream="stdout")


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_after(self):
        pass
