"""``launch.actions.shutdown_action``, where upstream defines it."""

from mlaunch.launch.actions import Shutdown

__all__ = ["Shutdown"]
