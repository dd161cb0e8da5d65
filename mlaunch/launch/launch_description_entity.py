"""``launch.launch_description_entity``, where upstream defines it."""

from mlaunch.launch.launch_description import LaunchDescriptionEntity

__all__ = ["LaunchDescriptionEntity"]
