"""``launch.actions.set_launch_configuration``, where upstream defines it."""

from mlaunch.launch.actions.scoping import SetLaunchConfiguration

__all__ = ["SetLaunchConfiguration"]
