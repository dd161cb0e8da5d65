"""``launch.action``, where upstream defines it."""

from mlaunch.launch.launch_description import Action

__all__ = ["Action"]
