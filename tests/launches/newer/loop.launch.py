"""Newer than Jazzy (launch 3.8+): ForEach, ForLoop, StringJoinSubstitution; the same system in .py, .yaml and .xml (tests/test_newer_syntax.py)."""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, ForEach, ForLoop, LogInfo
from launch.substitutions import LaunchConfiguration, StringJoinSubstitution


def for_each(name: str, id: int, opt: str = "none"):
    return [
        LogInfo(msg=f"'{name}' id={id} opt={opt}"),
        ExecuteProcess(cmd=["echo", name], name=f"echo-{name}"),
    ]


def for_i(i: int):
    return [LogInfo(msg=["i=", str(i)])]


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "robots", default_value="{name: 'robotA', id: 1};{name: 'robotB', id: 2}"
            ),
            DeclareLaunchArgument("num", default_value="2"),
            ForEach(LaunchConfiguration("robots"), function=for_each),
            ForLoop(LaunchConfiguration("num"), function=for_i),
            LogInfo(
                msg=StringJoinSubstitution(
                    [["https://", LaunchConfiguration("num")], "ros", "org"], delimiter="."
                )
            ),
        ]
    )
