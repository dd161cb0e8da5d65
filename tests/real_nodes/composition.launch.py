"""The composition demo's components in a container: real ones where the real nodes are built
(scripts/setup --real-nodes), which tests/test_real_nodes.py checks."""

from launch import LaunchDescription
from launch_ros.actions import ComposableNodeContainer
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    return LaunchDescription(
        [
            ComposableNodeContainer(
                name="demo_container",
                namespace="",
                package="rclcpp_components",
                executable="component_container",
                composable_node_descriptions=[
                    ComposableNode(
                        package="composition", plugin="composition::Talker", name="talker"
                    ),
                    ComposableNode(
                        package="composition", plugin="composition::Listener", name="listener"
                    ),
                ],
                output="screen",
            )
        ]
    )
