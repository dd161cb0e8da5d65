# environment actions: set, unset, append, prepend, push/pop, reset
from launch import LaunchDescription
from launch.actions import (
    AppendEnvironmentVariable,
    ExecuteProcess,
    PopEnvironment,
    PushEnvironment,
    SetEnvironmentVariable,
    UnsetEnvironmentVariable,
)
from launch.substitutions import EnvironmentVariable, FindExecutable
from launch_ros.substitutions import ExecutableInPackage


def rec(tag):
    from launch_ros.substitutions import ExecutableInPackage

    return ExecuteProcess(cmd=[ExecutableInPackage("recorder", "conf_pkg"), tag], name=tag)


def generate_launch_description():
    return LaunchDescription(
        [
            SetEnvironmentVariable("CONF_A", "alpha"),
            AppendEnvironmentVariable("CONF_LIST", "one"),
            AppendEnvironmentVariable("CONF_LIST", "two"),
            AppendEnvironmentVariable("CONF_LIST", "zero", prepend=True),
            AppendEnvironmentVariable("CONF_SEP", "x", separator=";"),
            AppendEnvironmentVariable("CONF_SEP", "y", separator=";"),
            rec("first"),
            PushEnvironment(),
            SetEnvironmentVariable("CONF_B", [EnvironmentVariable("CONF_A"), "-beta"]),
            UnsetEnvironmentVariable("CONF_A"),
            rec("pushed"),
            PopEnvironment(),
            rec("popped"),
            ExecuteProcess(
                cmd=[
                    FindExecutable(name="env"),
                    "CONF_X=1",
                    ExecutableInPackage("recorder", "conf_pkg"),
                ],
                name="via_env",
                additional_env={"CONF_ADD": "added"},
                cwd="/tmp",
                shell=False,
            ),
        ]
    )
