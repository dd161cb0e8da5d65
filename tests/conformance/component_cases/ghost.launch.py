# loads: 1 -- a LoadComposableNodes into a container that never starts: launch_ros waits until shutdown and says it abandons the wait
from launch import LaunchDescription
from launch_ros.actions import ComposableNodeContainer, LoadComposableNodes
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    return LaunchDescription(
        [
            LoadComposableNodes(
                target_container="ghost_ns/ghost",
                composable_node_descriptions=[
                    ComposableNode(package="demo", plugin="demo::Never", name="never"),
                    ComposableNode(package="demo", plugin="demo::NeverEither", name="never2"),
                ],
            ),
            ComposableNodeContainer(
                package="conf_pkg",
                executable="recording_container",
                name="real",
                namespace="",
                composable_node_descriptions=[
                    ComposableNode(package="demo", plugin="demo::Real", name="real_node"),
                ],
            ),
        ]
    )
