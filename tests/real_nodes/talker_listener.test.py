"""launch_testing on the real C++ talker and listener of demo_nodes_cpp (scripts/setup
--real-nodes builds them; mlaunch has no stand-in for either, so only the real ones can run)."""

import unittest

import launch
import launch_ros.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts


def generate_test_description():
    talker = launch_ros.actions.Node(package="demo_nodes_cpp", executable="talker", output="screen")
    listener = launch_ros.actions.Node(
        package="demo_nodes_cpp", executable="listener", output="screen"
    )
    nodes = {"talker": talker, "listener": listener}
    return launch.LaunchDescription([talker, listener, launch_testing.actions.ReadyToTest()]), nodes


class TestChatter(unittest.TestCase):
    def test_talker_publishes(self, proc_output, talker):
        proc_output.assertWaitFor("Publishing: 'Hello World: 1'", process=talker, timeout=30)

    def test_listener_hears_the_talker(self, proc_output, listener):
        proc_output.assertWaitFor("I heard: [Hello World: ", process=listener, timeout=30)


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_exit_codes(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)
