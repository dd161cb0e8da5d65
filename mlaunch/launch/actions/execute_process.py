"""``launch.actions.execute_process``, where upstream defines it."""

from mlaunch.launch.actions import ExecuteProcess

__all__ = ["ExecuteProcess"]
