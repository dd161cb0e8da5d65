"""Processes started from inside active tests with launch_testing.tools.launch_process, and
a launch argument read by the description and by the tests."""

import os
import sys
import unittest

import launch
import launch.actions
import launch.substitutions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import launch_testing.markers
import launch_testing.tools

CHATTER = os.path.join(os.path.dirname(__file__), "chatter.py")


def chatter(*args):
    return launch.actions.ExecuteProcess(cmd=[sys.executable, CHATTER, *args], output="screen")


@launch_testing.markers.keep_alive
def generate_test_description():
    greeter = chatter("--count", "0", launch.substitutions.LaunchConfiguration("greeting"))
    return (
        launch.LaunchDescription(
            [
                launch.actions.DeclareLaunchArgument("greeting", default_value="plain"),
                greeter,
                launch_testing.actions.ReadyToTest(),
            ]
        ),
        {"greeter": greeter},
    )


class TestLaunchedFromTests(unittest.TestCase):
    def test_greeting_argument(self, proc_output, greeter, test_args):
        proc_output.assertWaitFor(
            "hello " + test_args.get("greeting", "plain"),
            process=greeter,
            timeout=10,
            stream="stdout",
        )

    def test_one_shot(self, launch_service, proc_info, proc_output):
        action = chatter("--count", "2", "--exit", "4", "one-shot")
        with launch_testing.tools.launch_process(
            launch_service, action, proc_info, proc_output
        ) as proxy:
            proc_info.assertWaitForStartup(process=action, timeout=5)
            self.assertTrue(proxy.wait_for_shutdown(timeout=10))
            self.assertIn("count 1", proxy.stdout)
        self.assertEqual(proxy.exit_code, 4)
        launch_testing.asserts.assertExitCodes(proc_info, [4], process=action)

    def test_stopped_at_exit(self, launch_service, proc_info, proc_output):
        action = chatter("--count", "1", "lingering")
        with launch_testing.tools.launch_process(
            launch_service, action, proc_info, proc_output
        ) as proxy:
            self.assertTrue(proxy.wait_for_output(lambda out: "count 0" in out, timeout=10))
        proc_info.assertWaitForShutdown(process=action, timeout=10)
        self.assertIn("goodbye", proxy.stdout)


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_everything_exited_as_expected(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info, [0, 4])
