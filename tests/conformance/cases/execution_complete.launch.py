# OnExecutionComplete: fires for a TimerAction target; not for a process visited before its handler (item 3)
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler, TimerAction
from launch.event_handlers import OnExecutionComplete
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    timer = TimerAction(period=0.1, actions=[])
    early = ExecuteProcess(cmd=[rec, "early"], name="early")
    # It lingers past the timer, so the two completions come in one order under any load.
    late = ExecuteProcess(cmd=[rec, "late", "--linger", "0.5"], name="late")
    return LaunchDescription(
        [
            RegisterEventHandler(
                OnExecutionComplete(
                    target_action=timer, on_completion=[LogInfo(msg="timer complete")]
                )
            ),
            early,
            RegisterEventHandler(
                OnExecutionComplete(
                    target_action=early, on_completion=[LogInfo(msg="early complete")]
                )
            ),
            RegisterEventHandler(
                OnExecutionComplete(
                    target_action=late, on_completion=[LogInfo(msg="late complete")]
                )
            ),
            late,
            timer,
        ]
    )
