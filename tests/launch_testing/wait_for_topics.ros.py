"""launch_testing_ros.WaitForTopics against a ROS node of the launch (needs rclpy)."""

import os
import sys
import unittest

import launch
import launch_ros.actions
import launch_testing
import launch_testing.actions
import launch_testing_ros
from std_msgs.msg import String

TALKER = os.path.join(os.path.dirname(__file__), "..", "nodes", "talker.py")


def generate_test_description():
    talker = launch_ros.actions.Node(executable=sys.executable, arguments=[TALKER], name="talker")
    return launch.LaunchDescription([talker, launch_testing.actions.ReadyToTest()])


class TestTopics(unittest.TestCase):
    def test_chatter_arrives(self):
        with launch_testing_ros.WaitForTopics([("chatter", String)], timeout=30) as wait:
            self.assertEqual(wait.topics_received(), {"chatter"})
            self.assertTrue(wait.received_messages("chatter")[0].data.startswith("Hello World"))

    def test_silent_topic(self):
        wait = launch_testing_ros.WaitForTopics([("nobody_publishes", String)], timeout=0.5)
        try:
            self.assertFalse(wait.wait())
            self.assertEqual(wait.topics_not_received(), {"nobody_publishes"})
            with self.assertRaises(KeyError):
                wait.received_messages("elsewhere")
        finally:
            wait.shutdown()


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_exit_codes(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)
