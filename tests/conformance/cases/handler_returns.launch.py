# Handler callables may return None, one entity, or a list (item 2)
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit, OnProcessIO, OnProcessStart
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    p = ExecuteProcess(cmd=[rec, "--say", "line"], name="talker", output="screen")
    return LaunchDescription(
        [
            RegisterEventHandler(OnProcessStart(target_action=p, on_start=lambda ev, ctx: None)),
            RegisterEventHandler(
                OnProcessStart(
                    target_action=p, on_start=lambda ev, ctx: LogInfo(msg="single on start")
                )
            ),
            RegisterEventHandler(
                OnProcessIO(target_action=p, on_stdout=lambda ev: LogInfo(msg="single on io"))
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=p, on_exit=lambda ev, ctx: LogInfo(msg="single on exit")
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=p, on_exit=lambda ev, ctx: [LogInfo(msg="list on exit")]
                )
            ),
            RegisterEventHandler(
                OnProcessExit(target_action=p, on_exit=LogInfo(msg="entity on exit"))
            ),
            p,
        ]
    )
