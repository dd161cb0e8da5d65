"""``launch_testing_ros`` of ROS 2, on mlaunch: launch tests that talk to ROS.

``WaitForTopics`` waits for messages on topics, ``DataRepublisher`` republishes transformed
messages, ``MessagePump`` spins a node in a thread, ``tools.basic_output_filter`` also drops an
RMW implementation's own lines, and files whose generate_test_description is marked
``@pytest.mark.rostest`` run under pytest with the ROS LaunchTestRunner. rclpy is imported only
when a ROS object is made or spun (the ``ros`` extra provides it).
"""

from __future__ import annotations

from mlaunch.launch_testing_ros import tools
from mlaunch.launch_testing_ros.data_republisher import DataRepublisher
from mlaunch.launch_testing_ros.message_pump import MessagePump
from mlaunch.launch_testing_ros.test_runner import LaunchTestRunner
from mlaunch.launch_testing_ros.wait_for_topics import WaitForTopics

__all__ = ["DataRepublisher", "LaunchTestRunner", "MessagePump", "WaitForTopics", "tools"]
