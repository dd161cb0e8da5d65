from launch import LaunchDescription
from launch.actions import ExecuteProcess, ResetEnvironment, SetEnvironmentVariable
from launch.substitutions import EnvironmentVariable
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    rec = ExecutableInPackage("recorder", "conf_pkg")
    return LaunchDescription(
        [
            SetEnvironmentVariable("CONF_A", "alpha"),
            ResetEnvironment(),
            ExecuteProcess(
                cmd=[rec, "after_reset"],
                env={"ONLY": "this", "CONF_RECORD_DIR": EnvironmentVariable("CONF_RECORD_DIR")},
                name="with_env",
            ),
            ExecuteProcess(cmd=[rec, "plain"], name="plain"),
        ]
    )
