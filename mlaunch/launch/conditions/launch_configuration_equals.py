"""``launch.conditions.launch_configuration_equals``, where upstream defines it."""

from mlaunch.launch.conditions import LaunchConfigurationEquals

__all__ = ["LaunchConfigurationEquals"]
