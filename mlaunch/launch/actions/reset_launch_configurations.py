"""``launch.actions.reset_launch_configurations``, where upstream defines it."""

from mlaunch.launch.actions import ResetLaunchConfigurations

__all__ = ["ResetLaunchConfigurations"]
