"""``launch.actions.push_launch_configurations``, where upstream defines it."""

from mlaunch.launch.actions.scoping import PushLaunchConfigurations

__all__ = ["PushLaunchConfigurations"]
