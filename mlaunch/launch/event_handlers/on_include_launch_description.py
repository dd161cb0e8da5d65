"""``launch.event_handlers.on_include_launch_description``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnIncludeLaunchDescription

__all__ = ["OnIncludeLaunchDescription"]
