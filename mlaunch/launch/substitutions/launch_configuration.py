"""``launch.substitutions.launch_configuration``, where upstream defines it."""

from mlaunch.launch.substitutions import LaunchConfiguration

__all__ = ["LaunchConfiguration"]
