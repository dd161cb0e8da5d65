"""Tests that must fail: a text that never comes, and a process that exits 3."""

import os
import sys
import unittest

import launch
import launch.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import launch_testing.markers
import pytest

CHATTER = os.path.join(os.path.dirname(__file__), "chatter.py")


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    quitter = launch.actions.ExecuteProcess(
        cmd=[sys.executable, CHATTER, "--count", "1", "--exit", "3"], name="quitter"
    )
    return (
        launch.LaunchDescription([quitter, launch_testing.actions.ReadyToTest()]),
        {"quitter": quitter},
    )


class TestActive(unittest.TestCase):
    def test_never_printed(self, proc_output, quitter):
        proc_output.assertWaitFor("never printed", process=quitter, timeout=1, stream="stdout")

    def test_leaves(self, proc_info, quitter):
        proc_info.assertWaitForShutdown(process=quitter, timeout=10)


@launch_testing.post_shutdown_test()
class TestExit(unittest.TestCase):
    def test_exit_zero(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)

    def test_exit_three_allowed(self, proc_info, quitter):
        launch_testing.asserts.assertExitCodes(proc_info, [3], process=quitter)

    @unittest.skip("shows that a skip is reported as skipped")
    def test_skipped(self):
        pass
