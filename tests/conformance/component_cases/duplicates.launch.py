# loads: 4 -- node names counted as launch_ros counts them: a container answering a name it gave before (as rclcpp's do), a Node with the same full name, a warning under the container's name
from launch import LaunchDescription
from launch_ros.actions import ComposableNodeContainer, Node
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    return LaunchDescription(
        [
            Node(package="conf_pkg", executable="recording_container", name="taken", namespace="/"),
            ComposableNodeContainer(
                package="conf_pkg",
                executable="recording_container",
                name="box",
                namespace="",
                arguments=["--echo-names"],
                composable_node_descriptions=[
                    ComposableNode(package="demo", plugin="demo::A", name="dup"),
                    ComposableNode(package="demo", plugin="demo::B", name="dup"),
                    ComposableNode(package="demo", plugin="demo::C", name="taken"),
                    ComposableNode(package="demo", plugin="demo::D", name="dup", namespace="ns"),
                ],
            ),
        ]
    )
