"""Active tests wait on a running process's output; post-shutdown tests check what it did."""

import os
import sys
import unittest

import launch
import launch.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import pytest

CHATTER = os.path.join(os.path.dirname(__file__), "chatter.py")


@pytest.mark.launch_test
def generate_test_description():
    chatter = launch.actions.ExecuteProcess(
        cmd=[sys.executable, CHATTER, "--count", "4", "world"], name="chatter", output="screen"
    )
    return (
        launch.LaunchDescription([chatter, launch_testing.actions.ReadyToTest()]),
        {"chatter": chatter, "expected_count": 4},
    )


class TestWhileRunning(unittest.TestCase):
    def test_counts_to_three(self, proc_output, chatter):
        proc_output.assertWaitFor("count 3", process=chatter, timeout=10, stream="stdout")

    def test_is_running(self, proc_info, chatter):
        proc_info.assertWaitForStartup(process=chatter, timeout=5)

    def test_no_such_text_on_stderr(self, proc_output, chatter):
        self.assertFalse(proc_output.waitFor("count 0", process=chatter, timeout=0.5))


@launch_testing.post_shutdown_test()
class TestAfterShutdown(unittest.TestCase):
    def test_exit_code(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)

    def test_in_order(self, proc_output, chatter, expected_count):
        with launch_testing.asserts.assertSequentialStdout(proc_output, chatter) as cm:
            cm.assertInStdout("hello world")
            for k in range(expected_count):
                cm.assertInStdout(f"count {k}")
            cm.assertInStdout("goodbye")

    def test_out_of_order_is_noticed(self, proc_output, chatter):
        with (
            self.assertRaisesRegex(AssertionError, "'count 1' not found"),
            launch_testing.asserts.assertSequentialStdout(proc_output, chatter) as cm,
        ):
            cm.assertInStdout("count 2")
            cm.assertInStdout("count 1")

    def test_details(self, chatter):
        self.assertEqual(chatter.process_details["name"], "chatter-1")
        self.assertEqual(chatter.process_details["cmd"][-1], "world")
