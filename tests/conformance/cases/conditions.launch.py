# args: flag:=true mode:=sim
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo
from launch.conditions import (
    IfCondition,
    LaunchConfigurationEquals,
    LaunchConfigurationNotEquals,
    UnlessCondition,
)
from launch.substitutions import (
    AndSubstitution,
    EqualsSubstitution,
    LaunchConfiguration,
    NotEqualsSubstitution,
    NotSubstitution,
    OrSubstitution,
    PythonExpression,
)


def generate_launch_description():
    flag = LaunchConfiguration("flag")
    mode = LaunchConfiguration("mode")
    return LaunchDescription(
        [
            DeclareLaunchArgument("flag", default_value="false"),
            DeclareLaunchArgument("mode", default_value="real", choices=["real", "sim"]),
            LogInfo(msg="if flag", condition=IfCondition(flag)),
            LogInfo(msg="unless flag", condition=UnlessCondition(flag)),
            LogInfo(msg="mode is sim", condition=LaunchConfigurationEquals("mode", "sim")),
            LogInfo(msg="mode not real", condition=LaunchConfigurationNotEquals("mode", "real")),
            LogInfo(msg="and", condition=IfCondition(AndSubstitution(flag, "1"))),
            LogInfo(msg="or", condition=IfCondition(OrSubstitution("False", flag))),
            LogInfo(msg="not", condition=IfCondition(NotSubstitution("0"))),
            LogInfo(msg="equals", condition=IfCondition(EqualsSubstitution(mode, "sim"))),
            LogInfo(msg="not equals", condition=IfCondition(NotEqualsSubstitution(mode, "sim"))),
            LogInfo(
                msg="python",
                condition=IfCondition(
                    PythonExpression(["'", mode, "' == 'sim' and '", flag, "' == 'true'"])
                ),
            ),
            LogInfo(msg=["values ", flag, " ", mode]),
        ]
    )
