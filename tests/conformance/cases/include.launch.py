# args: top:=T
import os

from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    GroupAction,
    IncludeLaunchDescription,
    LogInfo,
    SetLaunchConfiguration,
)
from launch.launch_description_sources import (
    AnyLaunchDescriptionSource,
    FrontendLaunchDescriptionSource,
    PythonLaunchDescriptionSource,
)
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import PushRosNamespace
from launch_ros.substitutions import FindPackageShare

HERE = os.path.dirname(__file__)


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("top", default_value="t"),
            SetLaunchConfiguration("leak", "leaked"),
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource(os.path.join(HERE, "include_child.launch.py")),
                launch_arguments={"robot": LaunchConfiguration("top")}.items(),
            ),
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource([HERE, "/include_child.launch.py"])
            ),
            GroupAction(
                [
                    PushRosNamespace("grp"),
                    IncludeLaunchDescription(
                        FrontendLaunchDescriptionSource(
                            PathJoinSubstitution(
                                [
                                    FindPackageShare("conf_pkg"),
                                    "launch",
                                    "include_child.launch.yaml",
                                ]
                            )
                        ),
                        launch_arguments=[("robot", "yaml_bot")],
                    ),
                ]
            ),
            IncludeLaunchDescription(
                AnyLaunchDescriptionSource(os.path.join(HERE, "include_child.launch.xml")),
                launch_arguments={"robot": "any"}.items(),
            ),
            IncludeLaunchDescription(os.path.join(HERE, "include_child.launch.yaml")),
            LogInfo(msg=["after includes robot=", LaunchConfiguration("robot", default="unset")]),
        ]
    )
