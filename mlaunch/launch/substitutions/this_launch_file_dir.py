"""``launch.substitutions.this_launch_file_dir``, where upstream defines it."""

from mlaunch.launch.substitutions import ThisLaunchFileDir

__all__ = ["ThisLaunchFileDir"]
