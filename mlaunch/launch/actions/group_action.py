"""``launch.actions.group_action``, where upstream defines it."""

from mlaunch.launch.actions.scoping import GroupAction

__all__ = ["GroupAction"]
