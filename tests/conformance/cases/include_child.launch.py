from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("robot", default_value="p0"),
            LogInfo(
                msg=[
                    "child py robot=",
                    LaunchConfiguration("robot"),
                    " leak=",
                    LaunchConfiguration("leak", default="-"),
                ]
            ),
        ]
    )
