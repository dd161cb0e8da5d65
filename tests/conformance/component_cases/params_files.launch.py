# loads: 6 -- params files: '/**' and node-name sections, nested and slashed namespace keys, wildcards launch_ros does not match, files for other nodes, files without ros__parameters, a global file, allow_substs
import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch_ros.actions import (
    ComposableNodeContainer,
    PushROSNamespace,
    SetParametersFromFile,
)
from launch_ros.descriptions import ComposableNode
from launch_ros.parameter_descriptions import ParameterFile

HERE = os.path.dirname(__file__)


def f(name):
    return os.path.join(HERE, name)


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("level", default_value="3"),
            SetParametersFromFile(f("global.yaml")),
            GroupAction(
                [
                    PushROSNamespace("ns"),
                    ComposableNodeContainer(
                        package="conf_pkg",
                        executable="recording_container",
                        name="files",
                        namespace="/",
                        composable_node_descriptions=[
                            ComposableNode(
                                package="demo",
                                plugin="demo::Typed",
                                name="typed",
                                namespace="/",
                                parameters=[f("params.yaml"), {"after": "dict"}],
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Inner",
                                name="inner",
                                parameters=[f("params.yaml")],
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Slashed",
                                name="slashed",
                                parameters=[{"before": 1}, f("params.yaml")],
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Others",
                                name="lonely",
                                parameters=[{"kept": "x"}, f("others.yaml"), f("plain.yaml")],
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Unnamed",
                                parameters=[f("params.yaml")],
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Substs",
                                name="substs",
                                parameters=[ParameterFile(f("substs.yaml"), allow_substs=True)],
                            ),
                        ],
                    ),
                ]
            ),
        ]
    )
