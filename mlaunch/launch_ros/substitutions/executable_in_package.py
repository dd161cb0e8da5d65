"""``launch_ros.substitutions.executable_in_package``, where upstream defines it."""

from mlaunch.launch_ros.substitutions import ExecutableInPackage

__all__ = ["ExecutableInPackage"]
