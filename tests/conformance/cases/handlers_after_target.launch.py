# The tutorials' order: the handler is registered after its target in the same list (item 1)
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit, OnProcessIO, OnProcessStart
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    p = ExecuteProcess(cmd=[rec, "--say", "hi"], name="target", output="screen")
    return LaunchDescription(
        [
            p,
            RegisterEventHandler(
                OnProcessStart(target_action=p, on_start=[LogInfo(msg="saw start")])
            ),
            RegisterEventHandler(
                OnProcessIO(target_action=p, on_stdout=lambda ev: [LogInfo(msg="saw output")])
            ),
            RegisterEventHandler(OnProcessExit(target_action=p, on_exit=[LogInfo(msg="saw exit")])),
        ]
    )
