# loads: 3 -- navigation2's bringup pattern: a container Node in a pushed namespace, an included file whose conditional group loads into '<namespace>/<container_name>' (a tuple of substitutions) with a params file, list and bool parameters from launch arguments, global use_sim_time and remaps
import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, IncludeLaunchDescription
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushROSNamespace

HERE = os.path.dirname(__file__)


def generate_launch_description():
    namespace = LaunchConfiguration("namespace")
    use_composition = LaunchConfiguration("use_composition")
    return LaunchDescription(
        [
            DeclareLaunchArgument("namespace", default_value="robot1"),
            DeclareLaunchArgument("use_composition", default_value="True"),
            DeclareLaunchArgument("use_sim_time", default_value="true"),
            GroupAction(
                [
                    PushROSNamespace(namespace),
                    Node(
                        condition=IfCondition(use_composition),
                        name="nav2_container",
                        package="conf_pkg",
                        executable="recording_container",
                        parameters=[{"autostart": True}],
                        remappings=[("/tf", "tf"), ("/tf_static", "tf_static")],
                    ),
                    IncludeLaunchDescription(
                        PythonLaunchDescriptionSource(os.path.join(HERE, "nav2_like_child.py")),
                        launch_arguments={
                            "namespace": namespace,
                            "container_name": "nav2_container",
                            "use_composition": use_composition,
                            "params_file": os.path.join(HERE, "nav2_params.yaml"),
                        }.items(),
                    ),
                ]
            ),
        ]
    )
