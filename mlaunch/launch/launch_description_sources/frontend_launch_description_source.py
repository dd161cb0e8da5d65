"""``launch.launch_description_sources.frontend_launch_description_source``."""

from mlaunch.launch.launch_description_sources import FrontendLaunchDescriptionSource

__all__ = ["FrontendLaunchDescriptionSource"]
