"""``launch_ros.actions.set_remap``, where upstream defines it."""

from mlaunch.launch_ros.actions import SetRemap

__all__ = ["SetRemap"]
