# loads: 5 -- loads written in a timer and in an event handler: a TimerAction's LoadComposableNodes (also one inside a group with a pushed namespace and a global parameter), a container started by OnProcessStart's handler with its nodes, a LoadComposableNodes in OnProcessStart
from launch import LaunchDescription
from launch.actions import GroupAction, RegisterEventHandler, TimerAction
from launch.event_handlers import OnProcessStart
from launch_ros.actions import (
    ComposableNodeContainer,
    LoadComposableNodes,
    Node,
    PushROSNamespace,
    SetParameter,
    SetRemap,
)
from launch_ros.descriptions import ComposableNode


def container(name):
    return ComposableNodeContainer(
        package="conf_pkg", executable="recording_container", name=name, namespace=""
    )


def generate_launch_description():
    first = container("first")
    trigger = Node(package="conf_pkg", executable="recording_container", name="trigger")
    return LaunchDescription(
        [
            first,
            TimerAction(
                period=0.5,
                actions=[
                    LoadComposableNodes(
                        target_container=first,
                        composable_node_descriptions=[
                            ComposableNode(package="demo", plugin="demo::Timed", name="timed")
                        ],
                    )
                ],
            ),
            Node(package="conf_pkg", executable="recording_container", name="grouped"),
            GroupAction(
                [
                    PushROSNamespace("later"),
                    SetParameter(name="in_group", value=True),
                    SetRemap(src="a", dst="b"),
                    TimerAction(
                        period=0.5,
                        actions=[
                            LoadComposableNodes(
                                target_container="/grouped",
                                composable_node_descriptions=[
                                    ComposableNode(
                                        package="demo", plugin="demo::InTimer", name="in_timer"
                                    )
                                ],
                            )
                        ],
                    ),
                ]
            ),
            trigger,
            RegisterEventHandler(
                OnProcessStart(
                    target_action=trigger,
                    on_start=[
                        ComposableNodeContainer(
                            package="conf_pkg",
                            executable="recording_container",
                            name="started_by_handler",
                            namespace="",
                            composable_node_descriptions=[
                                ComposableNode(
                                    package="demo", plugin="demo::FromHandler", name="h1"
                                ),
                                ComposableNode(
                                    package="demo", plugin="demo::FromHandler", name="h2"
                                ),
                            ],
                        ),
                        LoadComposableNodes(
                            target_container="/trigger",
                            composable_node_descriptions=[
                                ComposableNode(package="demo", plugin="demo::OnStart", name="s")
                            ],
                        ),
                    ],
                )
            ),
        ]
    )
