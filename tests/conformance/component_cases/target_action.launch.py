# loads: 5 -- target_container given as the container action (in a pushed namespace, named by a launch argument), loaded from another namespace, a refused load (named and unnamed), a skipped LoadComposableNodes, a container whose every node is skipped
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import ComposableNodeContainer, LoadComposableNodes, PushROSNamespace
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    container = ComposableNodeContainer(
        package="conf_pkg",
        executable="recording_container",
        name=LaunchConfiguration("container_name"),
        namespace="",
        arguments=["--fail", "demo::Broken"],
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument("container_name", default_value="box"),
            GroupAction([PushROSNamespace("robot"), container]),
            ComposableNodeContainer(
                package="conf_pkg",
                executable="recording_container",
                name="idle",
                namespace="",
                composable_node_descriptions=[
                    ComposableNode(
                        package="demo", plugin="demo::Never", condition=IfCondition("false")
                    )
                ],
            ),
            GroupAction(
                [
                    PushROSNamespace("other"),
                    LoadComposableNodes(
                        target_container=container,
                        composable_node_descriptions=[
                            ComposableNode(package="demo", plugin="demo::First", name="first"),
                            ComposableNode(package="demo", plugin="demo::Broken", name="broken"),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Third",
                                name="third",
                                namespace="deep",
                                parameters=[{"container": LaunchConfiguration("container_name")}],
                            ),
                            ComposableNode(package="demo", plugin="demo::Unnamed"),
                            ComposableNode(package="demo", plugin="demo::Broken"),
                        ],
                    ),
                ]
            ),
            LoadComposableNodes(
                target_container=container,
                condition=IfCondition("false"),
                composable_node_descriptions=[
                    ComposableNode(package="demo", plugin="demo::Skipped", name="skipped")
                ],
            ),
        ]
    )
