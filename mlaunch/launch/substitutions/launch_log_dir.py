"""``launch.substitutions.launch_log_dir``, where upstream defines it."""

from mlaunch.launch.substitutions import LaunchLogDir

__all__ = ["LaunchLogDir"]
