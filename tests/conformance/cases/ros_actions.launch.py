import os

from launch import LaunchDescription
from launch.actions import GroupAction
from launch_ros.actions import (
    Node,
    PushRosNamespace,
    SetParametersFromFile,
    SetRemap,
    SetUseSimTime,
)
from launch_ros.parameter_descriptions import ParameterFile

HERE = os.path.dirname(__file__)


def generate_launch_description():
    return LaunchDescription(
        [
            SetUseSimTime(True),
            SetParametersFromFile(os.path.join(HERE, "params.yaml")),
            GroupAction(
                [
                    PushRosNamespace("robot"),
                    SetRemap(src="/tf", dst="tf"),
                    Node(
                        package="conf_pkg",
                        executable="recorder",
                        name="with_file",
                        exec_name="renamed",
                        parameters=[
                            os.path.join(HERE, "params.yaml"),
                            ParameterFile(os.path.join(HERE, "params.yaml"), allow_substs=True),
                            {"x": 1},
                        ],
                        ros_arguments=["--log-level", "warn"],
                        arguments=["--say", "hi"],
                    ),
                ]
            ),
            Node(package="conf_pkg", executable="recorder"),
        ]
    )
