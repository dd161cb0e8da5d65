"""``launch.conditions.launch_configuration_not_equals``, where upstream defines it."""

from mlaunch.launch.conditions import LaunchConfigurationNotEquals

__all__ = ["LaunchConfigurationNotEquals"]
