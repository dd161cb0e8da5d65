# args: a:=cli
from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    GroupAction,
    LogInfo,
    OpaqueFunction,
    PopLaunchConfigurations,
    PushLaunchConfigurations,
    ResetLaunchConfigurations,
    SetLaunchConfiguration,
    UnsetLaunchConfiguration,
)
from launch.substitutions import LaunchConfiguration as LC


def show(context):
    keys = sorted(k for k in context.launch_configurations if k in ("a", "b", "c", "d"))
    return [
        LogInfo(msg="configs " + ",".join(f"{k}={context.launch_configurations[k]}" for k in keys))
    ]


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("a", default_value="default"),
            SetLaunchConfiguration("b", "bee"),
            OpaqueFunction(function=show),
            PushLaunchConfigurations(),
            SetLaunchConfiguration("c", "sea"),
            UnsetLaunchConfiguration("b"),
            OpaqueFunction(function=show),
            PopLaunchConfigurations(),
            OpaqueFunction(function=show),
            GroupAction([SetLaunchConfiguration("d", "dee"), OpaqueFunction(function=show)]),
            OpaqueFunction(function=show),
            GroupAction([OpaqueFunction(function=show)], launch_configurations={"d": LC("a")}),
            GroupAction([ResetLaunchConfigurations({"c": "only"}), OpaqueFunction(function=show)]),
            OpaqueFunction(function=show),
            LogInfo(msg=["a=", LC("a"), " b=", LC("b")]),
        ]
    )
