from launch import LaunchDescription
from launch.actions import (
    EmitEvent,
    ExecuteProcess,
    LogInfo,
    RegisterEventHandler,
    Shutdown,
    TimerAction,
)
from launch.event_handlers import OnProcessExit, OnShutdown
from launch.events import Shutdown as ShutdownEvent
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    quick = ExecuteProcess(cmd=[rec, "quick", "--wait-for", "--linger"], name="quick")
    return LaunchDescription(
        [
            ExecuteProcess(cmd=[rec, "--linger", "20"], name="lingers"),
            quick,
            RegisterEventHandler(
                OnShutdown(
                    on_shutdown=lambda ev, ctx: [LogInfo(msg="shutdown because " + ev.reason)]
                )
            ),
            RegisterEventHandler(
                OnProcessExit(target_action=quick, on_exit=[Shutdown(reason="quick is done")])
            ),
            TimerAction(period=10.0, actions=[EmitEvent(event=ShutdownEvent(reason="timeout"))]),
        ]
    )
