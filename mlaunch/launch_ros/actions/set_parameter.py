"""``launch_ros.actions.set_parameter``, where upstream defines it."""

from mlaunch.launch_ros.actions import SetParameter

__all__ = ["SetParameter"]
