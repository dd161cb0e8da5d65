# loads: 8 -- namespaces, remaps, global parameters, typed dict parameters, extra arguments,
# conditions, target by name, a container started elsewhere, a refused load.
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import (
    ComposableNodeContainer,
    LoadComposableNodes,
    Node,
    PushROSNamespace,
    SetParameter,
    SetRemap,
)
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    flag = LaunchConfiguration("flag")
    return LaunchDescription(
        [
            DeclareLaunchArgument("flag", default_value="false"),
            SetParameter(name="use_sim_time", value=True),
            SetRemap(src="/tf", dst="tf"),
            ComposableNodeContainer(
                package="conf_pkg",
                executable="recording_container",
                name="box",
                namespace="",
                arguments=["--fail", "demo::Broken"],
                composable_node_descriptions=[
                    ComposableNode(
                        package="demo",
                        plugin="demo::Typed",
                        name="typed",
                        parameters=[
                            {
                                "b": True,
                                "i": 3,
                                "f": 2.5,
                                "s": "text",
                                "empty": "",
                                "numeric_text": "42",
                                "bl": [True, False],
                                "il": [1, 2, 3],
                                "fl": [1.0, 2.5],
                                "mixed": [1, 2.5],
                                "sl": ["a", "b"],
                                "nested": {"inner": {"deep": 7}, "flag": False},
                                "subst": flag,
                                "subst_list": [flag, "x"],
                            },
                            {"i": 4},
                        ],
                        remappings=[("chatter", "chat"), ("/abs", "rel")],
                        extra_arguments=[{"use_intra_process_comms": True}, {"other": "x"}],
                    ),
                    ComposableNode(
                        package="demo",
                        plugin="demo::Skipped",
                        name="skipped",
                        condition=IfCondition(flag),
                    ),
                    ComposableNode(
                        package="demo",
                        plugin="demo::Kept",
                        name="kept",
                        namespace="ns",
                        condition=UnlessCondition(flag),
                    ),
                    ComposableNode(package="demo", plugin="demo::Broken", name="broken"),
                    ComposableNode(package="demo", plugin="demo::Anonymous"),
                ],
            ),
            Node(
                package="conf_pkg",
                executable="recording_container",
                name="elsewhere",
                namespace="outside",
            ),
            GroupAction(
                [
                    PushROSNamespace("robot"),
                    SetRemap(src="cmd", dst="cmd_vel"),
                    SetParameter(name="in_group", value=1),
                    LoadComposableNodes(
                        target_container="/outside/elsewhere",
                        composable_node_descriptions=[
                            ComposableNode(package="demo", plugin="demo::Grouped", name="grouped"),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Absolute",
                                name="absolute",
                                namespace="/abs",
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Relative",
                                name="relative",
                                namespace="sub",
                                remappings=[("in", "out")],
                                condition=UnlessCondition(flag),
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Dropped",
                                name="dropped",
                                condition=IfCondition(flag),
                            ),
                        ],
                    ),
                ]
            ),
            Node(package="conf_pkg", executable="recording_container", name="spare"),
            LoadComposableNodes(
                target_container="spare",
                composable_node_descriptions=[
                    ComposableNode(package="demo", plugin="demo::After", name="after"),
                ],
            ),
        ]
    )
