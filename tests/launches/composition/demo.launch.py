"""Composable nodes, the Python way: the same loads as demo.launch.xml and demo.launch.yaml."""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution, ThisLaunchFileDir
from launch_ros.actions import (
    ComposableNodeContainer,
    LoadComposableNodes,
    PushRosNamespace,
    SetParameter,
    SetRemap,
)
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    params = PathJoinSubstitution([ThisLaunchFileDir(), "params.yaml"])
    container = ComposableNodeContainer(
        name=LaunchConfiguration("container"),
        namespace="",
        package="rclcpp_components",
        executable="component_container",
        composable_node_descriptions=[
            ComposableNode(
                package="composition",
                plugin="composition::Talker",
                name="talker",
                parameters=[{"a": 1}, {"b": {"c": [1.0, 2.0]}}, params],
                remappings=[("chatter", "chat")],
                extra_arguments=[{"use_intra_process_comms": True}],
            ),
            ComposableNode(
                package="composition",
                plugin="composition::Listener",
                name="listener",
                condition=IfCondition(LaunchConfiguration("with_listener")),
            ),
        ],
        output="screen",
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument("container", default_value="my_container"),
            DeclareLaunchArgument("with_listener", default_value="true"),
            SetParameter("use_sim_time", True),
            container,
            GroupAction(
                [
                    PushRosNamespace("robot"),
                    SetRemap("/tf", "tf"),
                    LoadComposableNodes(
                        target_container=LaunchConfiguration("container"),
                        composable_node_descriptions=[
                            ComposableNode(
                                package="composition",
                                plugin="composition::Client",
                                name="client",
                                parameters=[params],
                            ),
                            ComposableNode(
                                package="composition",
                                plugin="composition::Server",
                                name="server",
                                namespace="srv",
                                parameters=[params],
                            ),
                        ],
                    ),
                ]
            ),
        ]
    )
