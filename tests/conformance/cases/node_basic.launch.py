# args: rate:=20
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("rate", default_value="10"),
            Node(
                package="conf_pkg",
                executable="recorder",
                name="talker",
                namespace="robot",
                parameters=[
                    {"rate": LaunchConfiguration("rate"), "names": ["a", "b"], "ratio": 0.5}
                ],
                remappings=[("chatter", "talk")],
                arguments=["--say", "hello"],
                output="screen",
            ),
        ]
    )
