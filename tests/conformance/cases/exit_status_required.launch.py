# A required process that fails: launch exits 0, mlaunch 1 (on purpose, README: exit status)
from launch import LaunchDescription
from launch.actions import ExecuteProcess, Shutdown
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    return LaunchDescription(
        [ExecuteProcess(cmd=[rec, "--exit", "4"], name="required", on_exit=Shutdown())]
    )
