from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import ComposableNodeContainer
from launch_ros.descriptions import ComposableLifecycleNode, ComposableNode


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("up", default_value="true"),
            ComposableNodeContainer(
                package="rclcpp_components",
                executable="component_container",
                name="c",
                namespace="",
                composable_node_descriptions=[
                    ComposableNode(package="p", plugin="p::Plain", name="plain"),
                    ComposableLifecycleNode(
                        package="p",
                        plugin="p::N",
                        name="n",
                        namespace="/robot",
                        autostart=LaunchConfiguration("up"),
                    ),
                ],
            ),
        ]
    )
