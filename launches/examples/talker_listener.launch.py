"""A talker and a listener under a namespace, with arguments, parameters and remaps.

Run: AMENT_PREFIX_PATH=launches/examples/prefix mlaunch launches/examples/talker_listener.launch.py
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node, PushRosNamespace, SetParameter, SetRemap
from launch_ros.parameter_descriptions import ParameterFile, ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    ns = LaunchConfiguration("ns")
    verbose = LaunchConfiguration("verbose")
    listener_params = ParameterFile(
        PathJoinSubstitution([FindPackageShare("mlaunch_demo"), "config", "listener.yaml"])
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "ns", default_value="robot1", description="Namespace of both nodes"
            ),
            DeclareLaunchArgument("rate", default_value="5.0", description="Publish rate in Hz"),
            DeclareLaunchArgument("use_sim", default_value="false", choices=["true", "false"]),
            DeclareLaunchArgument("verbose", default_value="false"),
            GroupAction(
                [
                    PushRosNamespace(ns),
                    SetParameter(name="use_sim_time", value=LaunchConfiguration("use_sim")),
                    SetRemap(src="/rosout_agg", dst="rosout_all"),
                    Node(
                        package="mlaunch_demo",
                        executable="talker",
                        name="talker",
                        output="screen",
                        respawn=True,
                        respawn_delay=2.0,
                        arguments=["--greeting", "hello there"],
                        parameters=[
                            {"rate": LaunchConfiguration("rate")},
                            {"greeting": ParameterValue("hello", value_type=str)},
                            {"qos": {"depth": 10, "reliable": True}},
                            {"frames": ["base", "odom", "map"]},
                        ],
                        remappings=[("chatter", "chat")],
                        additional_env={"TALKER_MODE": "demo"},
                    ),
                    Node(
                        package="mlaunch_demo",
                        executable="listener",
                        name="listener",
                        namespace="ears",
                        ros_arguments=["--log-level", "debug"],
                        condition=IfCondition(verbose),
                        parameters=[listener_params],
                        remappings=[("chatter", ["/", ns, "/chat"])],
                    ),
                    Node(
                        package="mlaunch_demo",
                        executable="listener",
                        name="listener",
                        condition=UnlessCondition(verbose),
                        parameters=[listener_params],
                        remappings=[("chatter", "chat")],
                    ),
                ]
            ),
            Node(
                package="mlaunch_demo",
                executable="listener",
                exec_name="monitor",
                name="monitor",
                namespace="/tools",
                sigterm_timeout="1",
                sigkill_timeout="1",
                parameters=[{"watch": ["/", ns, "/chat"]}, {"ids": [1, 2, 3]}],
            ),
        ]
    )
