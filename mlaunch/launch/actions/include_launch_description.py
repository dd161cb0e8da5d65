"""``launch.actions.include_launch_description``, where upstream defines it."""

from mlaunch.launch.actions import IncludeLaunchDescription

__all__ = ["IncludeLaunchDescription"]
