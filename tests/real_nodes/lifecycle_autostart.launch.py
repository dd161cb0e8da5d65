"""The real C++ lifecycle demo (ros2/demos' lifecycle package) brought up by launch alone: the
talker under a LifecycleNode with autostart (launch_ros configures and activates it), and the
listener that prints what the talker publishes on lifecycle_chatter once active."""

from launch import LaunchDescription
from launch_ros.actions import LifecycleNode, Node


def generate_launch_description():
    return LaunchDescription(
        [
            LifecycleNode(
                package="lifecycle",
                executable="lifecycle_talker",
                name="lc_talker",
                namespace="",
                autostart=True,
                output="screen",
            ),
            Node(package="lifecycle", executable="lifecycle_listener", output="screen"),
        ]
    )
