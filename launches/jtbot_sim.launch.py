"""jtbot in simulation: simulator + world, robot_state_publisher, spawn, viewer.

The same shape as the seed's launch file (a ROS 2 user's), with its arguments made explicit:
    mlaunch launches/jtbot_sim.launch.py [use_sim_time:=true] [world:=FILE] [rviz:=true]
        [gui:=false] [x:=0.0] [y:=0.0] [yaw:=0.0] [robot_name:=jtbot]
On a machine without Gazebo or RViz, mlaunch runs its stand-ins for them.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.conditions import IfCondition
from launch.substitutions import (
    Command,
    IfElseSubstitution,
    LaunchConfiguration,
    PathJoinSubstitution,
)
from launch_ros.actions import Node, SetParameter
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    pkg_share = FindPackageShare("jtbot_description")
    use_sim_time = LaunchConfiguration("use_sim_time")
    world = LaunchConfiguration("world")
    robot_name = LaunchConfiguration("robot_name")

    robot_description = ParameterValue(
        Command(["xacro ", PathJoinSubstitution([pkg_share, "urdf", "jtbot.urdf.xacro"])]),
        value_type=str,
    )

    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "use_sim_time",
                default_value="true",
                description="Use the simulation clock (/clock) in every node",
            ),
            DeclareLaunchArgument(
                "world",
                default_value=PathJoinSubstitution([pkg_share, "world", "jt.world"]),
                description="SDF world file to load into the simulator",
            ),
            DeclareLaunchArgument(
                "rviz", default_value="true", description="Open the viewer (rviz2)"
            ),
            DeclareLaunchArgument(
                "gui",
                default_value="false",
                description="Run the Gazebo client too (gazebo instead of gzserver)",
            ),
            DeclareLaunchArgument("x", default_value="0.0", description="Spawn x [m]"),
            DeclareLaunchArgument("y", default_value="0.0", description="Spawn y [m]"),
            DeclareLaunchArgument("yaw", default_value="0.0", description="Spawn yaw [rad]"),
            DeclareLaunchArgument(
                "robot_name", default_value="jtbot", description="Name of the spawned model"
            ),
            # Every node below runs on the simulation clock when use_sim_time is true.
            SetParameter(name="use_sim_time", value=use_sim_time),
            ExecuteProcess(
                cmd=[
                    IfElseSubstitution(LaunchConfiguration("gui"), "gazebo", "gzserver"),
                    "--verbose",
                    world,
                    "-s",
                    "libgazebo_ros_init.so",
                    "-s",
                    "libgazebo_ros_factory.so",
                ],
                name="gazebo",
                output="screen",
            ),
            Node(
                package="robot_state_publisher",
                executable="robot_state_publisher",
                output="screen",
                parameters=[{"robot_description": robot_description}, {"use_sim_time": use_sim_time}],
            ),
            Node(
                package="gazebo_ros",
                executable="spawn_entity.py",
                arguments=[
                    "-entity", robot_name,
                    "-topic", "robot_description",
                    "-x", LaunchConfiguration("x"),
                    "-y", LaunchConfiguration("y"),
                    "-Y", LaunchConfiguration("yaw"),
                ],  # fmt: skip
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
