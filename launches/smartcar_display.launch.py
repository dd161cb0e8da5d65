"""ROS 2 launch file converted by 'mlaunch convert' from the ROS 1 file smartcar_display.launch.

Each action is preceded by the ROS 1 line it comes from; WARNING comments mark what
ROS 2 does differently (the mapping is in mlaunch's docs/ros1.md). Running the ROS 1
file with mlaunch resolves to the same plan as this file.
"""

# ROS 1 group parameters stay in their group under mlaunch (the comment below);
# under ros2 launch a SetParameter in a group also reaches the nodes after it.
# mlaunch: scoped-parameters
# $(dirname) in an include's argument, and after it, stays this file's folder under
# mlaunch (the comment below); under ros2 launch it is the included file's.
# mlaunch: scoped-file-locals

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, GroupAction
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import Command, LaunchConfiguration
from launch_ros.actions import Node, SetParameter
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription(
        [
            # smartcar_display.launch:12
            DeclareLaunchArgument(
                "urdf_file",
                default_value=[
                    "xacro '",
                    FindPackageShare("smartcar_description"),
                    "/urdf/smartcar.urdf.xacro'",
                ],
            ),
            # smartcar_display.launch:14
            DeclareLaunchArgument("gui", default_value="false"),
            # smartcar_display.launch:9
            SetParameter(name="use_sim_time", value=False),
            # smartcar_display.launch:18: ROS 1 node arbotix (arbotix_driver)
            # WARNING: arbotix_python arbotix_driver (the ArbotiX diff-drive controller) has no ROS
            # 2 package: it is replaced by a Gazebo simulator (gzserver; mlaunch's stand-in where
            # Gazebo is not installed) that drives the robot from /cmd_vel through the diff-drive
            # plugin of its URDF, and spawn_entity.py spawns robot_description as 'smartcar'; its
            # parameters (port, baud, rate, sync_write, sync_read, read_rate, write_rate,
            # controllers, sim) are not used
            ExecuteProcess(
                cmd=["gzserver", "-s", "libgazebo_ros_init.so", "-s", "libgazebo_ros_factory.so"],
                output="screen",
            ),
            # smartcar_display.launch:18
            Node(
                package="gazebo_ros",
                executable="spawn_entity.py",
                arguments=["-topic", "robot_description", "-entity", "smartcar"],
                output="screen",
            ),
            # smartcar_display.launch:23
            # WARNING: use_gui: ROS 2's joint_state_publisher has no GUI; joint_state_publisher_gui
            # (its own package) runs when use_gui is true
            GroupAction(
                [
                    # smartcar_display.launch:23: without the GUI (use_gui false)
                    Node(
                        package="joint_state_publisher",
                        executable="joint_state_publisher",
                        name="joint_state_publisher",
                        condition=UnlessCondition(LaunchConfiguration("gui")),
                    ),
                    # smartcar_display.launch:23: use_gui true: the GUI is its own package in ROS 2
                    Node(
                        package="joint_state_publisher_gui",
                        executable="joint_state_publisher_gui",
                        name="joint_state_publisher",
                        condition=IfCondition(LaunchConfiguration("gui")),
                    ),
                ],
            ),
            # smartcar_display.launch:26: ROS 1 robot_state_publisher/state_publisher is
            # robot_state_publisher in ROS 2
            # robot_description: the global parameter of smartcar_display.launch:15
            Node(
                package="robot_state_publisher",
                executable="robot_state_publisher",
                name="robot_state_publisher",
                parameters=[
                    {
                        "robot_description": ParameterValue(
                            Command(LaunchConfiguration("urdf_file"), on_stderr="warn"),
                            value_type=str,
                        ),
                        "publish_frequency": 20.0,
                    },
                ],
            ),
            # smartcar_display.launch:31: ROS 1 static_transform_publisher arguments, written as
            # tf2_ros's named options
            # WARNING: the period (100 ms) of ROS 1 tf static_transform_publisher is dropped:
            # tf2_ros publishes a static transform once, latched on /tf_static
            # WARNING: frame ids lose their leading '/' (tf2 rejects it)
            Node(
                package="tf2_ros",
                executable="static_transform_publisher",
                name="odom_left_wheel_broadcaster",
                arguments=[
                    "--x",
                    "0",
                    "--y",
                    "0",
                    "--z",
                    "0",
                    "--yaw",
                    "0",
                    "--pitch",
                    "0",
                    "--roll",
                    "0",
                    "--frame-id",
                    "base_link",
                    "--child-frame-id",
                    "left_front_link",
                ],
            ),
            # smartcar_display.launch:32: ROS 1 static_transform_publisher arguments, written as
            # tf2_ros's named options
            # WARNING: the period (100 ms) of ROS 1 tf static_transform_publisher is dropped:
            # tf2_ros publishes a static transform once, latched on /tf_static
            # WARNING: frame ids lose their leading '/' (tf2 rejects it)
            Node(
                package="tf2_ros",
                executable="static_transform_publisher",
                name="odom_right_wheel_broadcaster",
                arguments=[
                    "--x",
                    "0",
                    "--y",
                    "0",
                    "--z",
                    "0",
                    "--yaw",
                    "0",
                    "--pitch",
                    "0",
                    "--roll",
                    "0",
                    "--frame-id",
                    "base_link",
                    "--child-frame-id",
                    "right_front_link",
                ],
            ),
            # smartcar_display.launch:34: ROS 1 rviz/rviz is rviz2/rviz2 in ROS 2
            # WARNING: the RViz config $(find smartcar_description)/urdf.rviz is a ROS 1 RViz
            # config (Class: rviz/...): rviz2 cannot load ROS 1 configs (display classes rviz/...
            # are rviz_default_plugins/... in rviz2); save a new one from rviz2
            Node(
                package="rviz2",
                executable="rviz2",
                name="rviz",
                arguments=["-d", [FindPackageShare("smartcar_description"), "/urdf.rviz"]],
            ),
        ],
    )
