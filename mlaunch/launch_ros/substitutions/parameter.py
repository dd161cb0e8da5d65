"""``launch_ros.substitutions.parameter``, where upstream defines it."""

from mlaunch.launch_ros.substitutions import Parameter

__all__ = ["Parameter"]
