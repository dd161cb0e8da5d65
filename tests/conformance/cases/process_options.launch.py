from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.substitutions import LocalSubstitution
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    respawner = ExecuteProcess(
        cmd=[rec, "--exit", "3"],
        name="respawner",
        respawn=True,
        respawn_max_retries=2,
        respawn_delay=0.1,
    )
    return LaunchDescription(
        [
            ExecuteProcess(cmd=[rec, "shell $HOME"], shell=True, name="shell"),
            ExecuteProcess(cmd=[rec, "tty"], emulate_tty=True, name="tty", output="screen"),
            ExecuteProcess(
                cmd=[rec, "--say", "screen-line", "--err", "err-line"],
                output="screen",
                name="screen",
            ),
            ExecuteProcess(
                cmd=[rec, "--say", "log-line", "--err", "log-err"], output="log", name="log"
            ),
            ExecuteProcess(cmd=[rec, "--say", "both-line"], output="both", name="both"),
            ExecuteProcess(cmd=[rec, "prefixed"], prefix="env CONF_PREFIXED=1", name="prefixed"),
            respawner,
            RegisterEventHandler(
                OnProcessExit(
                    target_action=respawner,
                    on_exit=lambda ev, ctx: LogInfo(msg=f"exit code {ev.returncode}"),
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=respawner,
                    on_exit=[LogInfo(msg=["cmd ", LocalSubstitution("event.cmd[1]")])],
                )
            ),
        ]
    )
