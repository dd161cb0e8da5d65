"""``launch_ros.actions.set_ros_log_dir``, where upstream defines it."""

from mlaunch.launch_ros.actions import SetROSLogDir

__all__ = ["SetROSLogDir"]
