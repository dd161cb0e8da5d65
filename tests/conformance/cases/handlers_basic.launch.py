# OnProcessStart, OnProcessIO, OnProcessExit, OnShutdown registered before their target
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit, OnProcessIO, OnProcessStart, OnShutdown
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    first = ExecuteProcess(cmd=[rec, "--say", "ping", "--exit", "3"], name="first", output="screen")
    second = ExecuteProcess(cmd=[rec, "after-first"], name="second")
    return LaunchDescription(
        [
            RegisterEventHandler(
                OnProcessStart(target_action=first, on_start=[LogInfo(msg="first started")])
            ),
            RegisterEventHandler(
                OnProcessIO(
                    target_action=first,
                    on_stdout=lambda ev: [LogInfo(msg="io " + ev.text.decode().strip())],
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=first,
                    on_exit=lambda ev, ctx: [LogInfo(msg=f"first exited {ev.returncode}"), second],
                )
            ),
            RegisterEventHandler(
                OnProcessExit(target_action=second, on_exit=[LogInfo(msg="second exited")])
            ),
            RegisterEventHandler(OnShutdown(on_shutdown=[LogInfo(msg="shutting down")])),
            first,
        ]
    )
