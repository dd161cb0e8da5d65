"""``launch.actions.reset_launch_configurations``, where upstream defines it."""

from mlaunch.launch.actions.scoping import ResetLaunchConfigurations

__all__ = ["ResetLaunchConfigurations"]
