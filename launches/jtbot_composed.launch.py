"""jtbot with its state publisher as a component: a container, robot_state_publisher's
component loaded into it, joint_state_publisher and the viewer.

    mlaunch launches/jtbot_composed.launch.py [rviz:=true]

Without rclcpp_components, mlaunch's container stand-in hosts the state publisher.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import Command, LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import ComposableNodeContainer, Node
from launch_ros.descriptions import ComposableNode
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    pkg_share = FindPackageShare("jtbot_description")
    robot_description = ParameterValue(
        Command(["xacro ", PathJoinSubstitution([pkg_share, "urdf", "jtbot.urdf.xacro"])]),
        value_type=str,
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument("rviz", default_value="true", description="Open the viewer"),
            ComposableNodeContainer(
                name="jtbot_container",
                namespace="",
                package="rclcpp_components",
                executable="component_container",
                composable_node_descriptions=[
                    ComposableNode(
                        package="robot_state_publisher",
                        plugin="robot_state_publisher::RobotStatePublisher",
                        name="robot_state_publisher",
                        parameters=[{"robot_description": robot_description}],
                    ),
                ],
                output="screen",
            ),
            Node(
                package="joint_state_publisher",
                executable="joint_state_publisher",
                output="screen",
            ),
            Node(
                package="rviz2",
                executable="rviz2",
                name="rviz2",
                arguments=["-d", PathJoinSubstitution([pkg_share, "rviz", "jtbot.rviz"])],
                output="screen",
                condition=IfCondition(LaunchConfiguration("rviz")),
            ),
        ]
    )
