"""``launch.events.include_launch_description``, where upstream defines it."""

from mlaunch.launch.events import IncludeLaunchDescription

__all__ = ["IncludeLaunchDescription"]
