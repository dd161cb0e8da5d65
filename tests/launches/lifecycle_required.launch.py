"""A required lifecycle node that refuses to activate: mlaunch must end the launch with status 1.

/robot/camera (autostart, required=True, --fail-activate) configures, then answers the
activate request with failure; /robot/talker would otherwise run forever.
"""

import os
import sys

from launch import LaunchDescription
from launch_ros.actions import LifecycleNode, Node

NODES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "nodes")


def generate_launch_description():
    return LaunchDescription(
        [
            LifecycleNode(
                executable=sys.executable,
                arguments=[os.path.join(NODES, "lifecycle_node.py"), "--fail-activate"],
                name="camera",
                namespace="robot",
                exec_name="camera",
                output="screen",
                autostart=True,
                required=True,
            ),
            Node(
                executable=sys.executable,
                arguments=[os.path.join(NODES, "talker.py")],
                name="talker",
                namespace="robot",
                exec_name="talker",
                output="own_log",
            ),
        ]
    )
