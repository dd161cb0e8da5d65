"""``launch.launch_description_source``, where upstream defines it."""

from mlaunch.launch.launch_description_sources import LaunchDescriptionSource

__all__ = ["LaunchDescriptionSource"]
