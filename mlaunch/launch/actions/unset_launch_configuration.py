"""``launch.actions.unset_launch_configuration``, where upstream defines it."""

from mlaunch.launch.actions import UnsetLaunchConfiguration

__all__ = ["UnsetLaunchConfiguration"]
