"""``launch.actions.set_launch_configuration``, where upstream defines it."""

from mlaunch.launch.actions import SetLaunchConfiguration

__all__ = ["SetLaunchConfiguration"]
