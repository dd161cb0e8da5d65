"""jtbot_sim plus one node that crashes 3 s after its process starts: ``mlaunch test`` must fail it, every
time (scripts/smoke_repeat.py runs both 20 times)."""

import os
import sys

from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch_ros.actions import Node

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def generate_launch_description():
    return LaunchDescription(
        [
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource(os.path.join(ROOT, "launches", "jtbot_sim.launch.py"))
            ),
            Node(
                executable=sys.executable,
                arguments=[
                    os.path.join(ROOT, "tests", "nodes", "crasher.py"),
                    "--crash-after",
                    "3",
                ],
                name="crasher",
                output="screen",
            ),
        ]
    )
