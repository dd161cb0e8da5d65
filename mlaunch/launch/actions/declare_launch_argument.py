"""``launch.actions.declare_launch_argument``, where upstream defines it."""

from mlaunch.launch.actions import DeclareLaunchArgument

__all__ = ["DeclareLaunchArgument"]
