"""Includes across formats: Python includes YAML (which includes Python, which includes XML)
and Python directly. Run: mlaunch launches/examples/include.launch.py robot:=r2
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, LogInfo
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_yaml.launch_description_sources import YAMLLaunchDescriptionSource


def generate_launch_description():
    robot = LaunchConfiguration("robot")
    # This file's folder, fixed here: after an include, ThisLaunchFileDir() in ros2 launch (Jazzy)
    # is the included file's (ros2/launch#618; mlaunch --scoped-file-locals keeps this file's).
    parts = os.path.join(os.path.dirname(__file__), "parts")
    return LaunchDescription(
        [
            DeclareLaunchArgument("robot", default_value="scout"),
            IncludeLaunchDescription(
                YAMLLaunchDescriptionSource(PathJoinSubstitution([parts, "sensors.launch.yaml"])),
                launch_arguments=[("camera", "front"), ("robot", robot)],
            ),
            # Includes are not scoped (as in ROS 2): the included file's let is visible here.
            LogInfo(msg=[robot, " has ", LaunchConfiguration("sensor_count"), " sensor(s)"]),
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource(PathJoinSubstitution([parts, "driver.launch.py"])),
                launch_arguments={"port": "/dev/ttyACM0"}.items(),
            ),
        ]
    )
