"""``launch.actions.pop_launch_configurations``, where upstream defines it."""

from mlaunch.launch.actions.scoping import PopLaunchConfigurations

__all__ = ["PopLaunchConfigurations"]
