"""``launch.launch_description_sources.any_launch_description_source``."""

from mlaunch.launch.launch_description_sources import AnyLaunchDescriptionSource

__all__ = ["AnyLaunchDescriptionSource"]
