"""``launch.actions.log_info``, where upstream defines it."""

from mlaunch.launch.actions import LogInfo

__all__ = ["LogInfo"]
