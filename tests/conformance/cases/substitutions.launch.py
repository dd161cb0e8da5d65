# args: who:=world
import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo, SetLaunchConfiguration
from launch.substitutions import (
    Command,
    EnvironmentVariable,
    FileContent,
    FindExecutable,
    IfElseSubstitution,
    LaunchConfiguration,
    PathJoinSubstitution,
    PythonExpression,
    TextSubstitution,
    ThisLaunchFile,
    ThisLaunchFileDir,
)
from launch_ros.substitutions import ExecutableInPackage, FindPackagePrefix, FindPackageShare


def generate_launch_description():
    here = os.path.dirname(__file__)
    return LaunchDescription(
        [
            DeclareLaunchArgument("who", default_value="nobody", description="who to greet"),
            SetLaunchConfiguration("greeting", ["hello ", LaunchConfiguration("who")]),
            LogInfo(msg=LaunchConfiguration("greeting")),
            LogInfo(msg=TextSubstitution(text="text")),
            LogInfo(msg=PathJoinSubstitution(["a", LaunchConfiguration("who"), "c.yaml"])),
            LogInfo(msg=PythonExpression(["str(6*7) + '", LaunchConfiguration("who"), "'"])),
            LogInfo(msg=IfElseSubstitution("true", "yes", "no")),
            LogInfo(
                msg=IfElseSubstitution(LaunchConfiguration("who"), if_value="a", else_value="b")
                if False
                else "skip"
            ),
            LogInfo(msg=EnvironmentVariable("CONF_UNSET_VAR", default_value="fallback")),
            LogInfo(msg=EnvironmentVariable("CONF_RECORD_DIR")),
            LogInfo(msg=Command(["echo ", LaunchConfiguration("who"), " from command"])),
            LogInfo(msg=Command("printf 'two\\nlines'")),
            LogInfo(msg=FileContent(os.path.join(here, "data.txt"))),
            LogInfo(msg=FindExecutable(name="sh")),
            LogInfo(msg=ThisLaunchFile()),
            LogInfo(msg=ThisLaunchFileDir()),
            LogInfo(msg=FindPackageShare("conf_pkg")),
            LogInfo(msg=FindPackagePrefix("conf_pkg")),
            LogInfo(msg=ExecutableInPackage("recorder", "conf_pkg")),
            LogInfo(msg=["list ", "of ", LaunchConfiguration("who", default="x")]),
            LogInfo(msg=LaunchConfiguration("undeclared", default="dflt")),
        ]
    )
