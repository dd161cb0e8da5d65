"""Groups, scopes, environment, conditions and timers, with plain programs (no ROS needed).

Run: mlaunch launches/examples/scoping.launch.py mode:=real
"""

from launch import LaunchDescription
from launch.actions import (
    AppendEnvironmentVariable,
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    LogInfo,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
    Shutdown,
    TimerAction,
    UnsetEnvironmentVariable,
)
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import EqualsSubstitution, LaunchConfiguration, PythonExpression


def generate_launch_description():
    mode = LaunchConfiguration("mode")
    workers = LaunchConfiguration("workers")
    site = LaunchConfiguration("site")
    is_real = EqualsSubstitution(mode, "real")
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "mode", default_value="sim", description="sim or real", choices=["sim", "real"]
            ),
            DeclareLaunchArgument("workers", default_value="2"),
            SetLaunchConfiguration("site", "lab"),
            SetEnvironmentVariable("SITE", site),
            AppendEnvironmentVariable("DEMO_PATH", "/opt/demo/bin"),
            AppendEnvironmentVariable("DEMO_PATH", "/opt/demo/first", prepend=True),
            GroupAction(
                [
                    SetLaunchConfiguration("site", "field"),
                    SetEnvironmentVariable("ZONE", "inner"),
                    ExecuteProcess(
                        cmd=["sh", "-c", "echo site=$SITE zone=$ZONE mode=$MODE"],
                        name="reporter",
                        additional_env={"MODE": mode},
                        output="screen",
                        sigterm_timeout="2",
                        sigkill_timeout="1",
                    ),
                    LogInfo(msg=["inside the group: site=", site]),
                ]
            ),
            LogInfo(msg=["after the group: site=", site]),
            GroupAction(
                [
                    LogInfo(
                        msg=[
                            "isolated: mode=",
                            mode,
                            " site=",
                            LaunchConfiguration("site", default="unset"),
                        ]
                    )
                ],
                forwarding=False,
                launch_configurations={"mode": mode},
            ),
            GroupAction(
                [
                    ExecuteProcess(
                        cmd=["python3", "-c", "import time; time.sleep(30)"],
                        name="hardware",
                        respawn=True,
                        respawn_delay=0.5,
                        respawn_max_retries=3,
                    )
                ],
                condition=IfCondition(is_real),
            ),
            ExecuteProcess(
                cmd=[
                    "python3",
                    "-c",
                    "import os; print('simulating', os.environ['WORKERS'], 'workers')",
                ],
                name="simulator",
                output="screen",
                condition=UnlessCondition(is_real),
                on_exit=[Shutdown()],
                additional_env={"WORKERS": workers},
            ),
            UnsetEnvironmentVariable("DEMO_PATH"),
            TimerAction(
                period=1.5,
                actions=[
                    LogInfo(msg=["timer fired in ", mode, " mode"]),
                    ExecuteProcess(
                        cmd=["sh", "-c", "echo late: $SITE ${DEMO_PATH:-no path}"],
                        name="late",
                        output="screen",
                    ),
                ],
            ),
            TimerAction(
                period=PythonExpression([workers, " * 2.5"]),
                cancel_on_shutdown=False,
                actions=[Shutdown(reason="demo over")],
            ),
        ]
    )
