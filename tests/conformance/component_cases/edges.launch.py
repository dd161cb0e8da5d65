# loads: 6 -- names, namespaces and remaps from substitutions, a container's own namespace (not the nodes'), empty, trailing-slash and nested namespaces, an absolute pushed namespace, a non-forwarding group, typed ParameterValues, text extra arguments, a global params file with a node section
import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.substitutions import LaunchConfiguration, PythonExpression, TextSubstitution
from launch_ros.actions import (
    ComposableNodeContainer,
    LoadComposableNodes,
    PushROSNamespace,
    SetParameter,
    SetParametersFromFile,
    SetRemap,
)
from launch_ros.descriptions import ComposableNode, ParameterValue

HERE = os.path.dirname(__file__)


def generate_launch_description():
    name = LaunchConfiguration("name")
    return LaunchDescription(
        [
            DeclareLaunchArgument("name", default_value="named"),
            SetParameter(name="global_before", value="g"),
            SetRemap(src=["/", name, "/in"], dst="remapped"),
            ComposableNodeContainer(
                package="conf_pkg",
                executable="recording_container",
                name="edge_box",
                namespace="container_ns",
            ),
            GroupAction(
                [
                    PushROSNamespace("inner"),
                    PushROSNamespace("sub"),
                    SetParametersFromFile(os.path.join(HERE, "node_section.yaml")),
                    LoadComposableNodes(
                        target_container="/container_ns/edge_box",
                        composable_node_descriptions=[
                            ComposableNode(
                                package=["de", "mo"],
                                plugin=PythonExpression(["'demo::' + 'Named'"]),
                                name=name,
                                parameters=[
                                    {
                                        "as_text": ParameterValue("5", value_type=str),
                                        "as_float": ParameterValue(
                                            TextSubstitution(text="5"), value_type=float
                                        ),
                                        "as_list": ParameterValue("[1, 2]"),
                                        "as_yaml": ParameterValue(name),
                                        "from_subst": [name, "_suffix"],
                                    }
                                ],
                                remappings=[(name, ["to_", name])],
                                extra_arguments=[
                                    {"use_intra_process_comms": "true", "second": 2},
                                    {"third": [1.5, 2.5]},
                                ],
                            ),
                            ComposableNode(
                                package="demo", plugin="demo::EmptyNs", name="empty", namespace=""
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::Trailing",
                                name="trailing",
                                namespace="tail/",
                            ),
                            ComposableNode(
                                package="demo",
                                plugin="demo::FromSubst",
                                name="from_subst",
                                namespace=["x_", name],
                            ),
                        ],
                    ),
                ]
            ),
            ComposableNodeContainer(
                package="conf_pkg", executable="recording_container", name="abs_box", namespace=""
            ),
            GroupAction(
                [
                    PushROSNamespace("/absolute_push"),
                    LoadComposableNodes(
                        target_container="abs_box",
                        composable_node_descriptions=[
                            ComposableNode(package="demo", plugin="demo::Abs", name="abs"),
                            ComposableNode(
                                package="demo", plugin="demo::Scoped", name=name, namespace="rel"
                            ),
                        ],
                    ),
                ],
                forwarding=False,
                launch_configurations={"name": "inside"},
            ),
        ]
    )
