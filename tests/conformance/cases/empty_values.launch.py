from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, SetParameter


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("empty", default_value=""),
            SetParameter(name="global_empty", value=LaunchConfiguration("empty")),
            Node(
                package="conf_pkg",
                executable="recorder",
                name="empties",
                parameters=[{"literal": "", "from_arg": LaunchConfiguration("empty")}],
            ),
        ]
    )
