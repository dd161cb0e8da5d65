"""A parametrized description: one launch per word, the tests named after it."""

import os
import sys
import unittest

import launch
import launch.actions
import launch_testing
import launch_testing.actions
import launch_testing.util

CHATTER = os.path.join(os.path.dirname(__file__), "chatter.py")


@launch_testing.parametrize("word, count", [("alpha", 1), ("beta", 2)])
def generate_test_description(word, count):
    chatter = launch.actions.ExecuteProcess(
        cmd=[sys.executable, CHATTER, "--count", str(count), "--exit", "0", word]
    )
    return (
        launch.LaunchDescription(
            [chatter, launch_testing.util.KeepAliveProc(), launch_testing.actions.ReadyToTest()]
        ),
        {"chatter": chatter},
    )


class TestEachWord(unittest.TestCase):
    def test_says_its_word(self, proc_output, chatter, word):
        proc_output.assertWaitFor("hello " + word, process=chatter, timeout=10, stream="stdout")

    def test_one_shot_ends(self, proc_info, chatter):
        proc_info.assertWaitForShutdown(process=chatter, timeout=10)


@launch_testing.post_shutdown_test()
class TestCounts(unittest.TestCase):
    def test_last_count(self, proc_output, chatter, count):
        launch_testing.asserts.assertInStdout(proc_output, f"count {count - 1}", chatter)

    def test_all_exit_zero(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)
