"""``launch.launch_description_sources.python_launch_description_source``."""

from mlaunch.launch.launch_description_sources import PythonLaunchDescriptionSource

__all__ = ["PythonLaunchDescriptionSource"]
