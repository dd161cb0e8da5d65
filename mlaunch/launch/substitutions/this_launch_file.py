"""``launch.substitutions.this_launch_file``, where upstream defines it."""

from mlaunch.launch.substitutions import ThisLaunchFile

__all__ = ["ThisLaunchFile"]
