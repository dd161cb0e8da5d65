# args: who:=cli
# Timer and handler bodies resolve when they fire: a configuration set later in the file applies (item 4)
from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    LogInfo,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
    TimerAction,
)
from launch.substitutions import EnvironmentVariable, LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace


def generate_launch_description():
    return LaunchDescription(
        [
            SetLaunchConfiguration("color", "red"),
            TimerAction(
                period=0.2,
                actions=[
                    LogInfo(
                        msg=[
                            "color=",
                            LaunchConfiguration("color"),
                            " who=",
                            LaunchConfiguration("who"),
                        ]
                    ),
                    LogInfo(msg=["env=", EnvironmentVariable("CONF_LATE", default_value="unset")]),
                    Node(package="conf_pkg", executable="recorder", name="late_node"),
                ],
            ),
            DeclareLaunchArgument("who", default_value="nobody"),
            SetLaunchConfiguration("color", "blue"),
            SetEnvironmentVariable("CONF_LATE", "set-later"),
            PushRosNamespace("later_ns"),
        ]
    )
