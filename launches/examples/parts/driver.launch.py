"""Included from YAML and XML: a device driver, which includes the XML logger for itself."""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, IncludeLaunchDescription
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    port = LaunchConfiguration("port")
    here = os.path.dirname(__file__)
    return LaunchDescription(
        [
            DeclareLaunchArgument("port", default_value="/dev/ttyUSB0"),
            ExecuteProcess(
                cmd=["python3", "-c", "import sys; print('driver on', sys.argv[1])", port],
                name="driver",
                respawn=True,
            ),
            IncludeLaunchDescription(
                AnyLaunchDescriptionSource(os.path.join(here, "logger.launch.xml")),
                launch_arguments={"source": ["driver:", port]}.items(),
            ),
        ]
    )
