"""``launch.actions.execute_local``, where upstream defines it."""

from mlaunch.launch.actions import ExecuteLocal

__all__ = ["ExecuteLocal"]
