"""``launch.actions.include_launch_description``, where upstream defines it."""

from mlaunch.launch.actions.scoping import IncludeLaunchDescription

__all__ = ["IncludeLaunchDescription"]
