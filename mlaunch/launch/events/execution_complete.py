"""``launch.events.execution_complete``, where upstream defines it."""

from mlaunch.launch.events import ExecutionComplete

__all__ = ["ExecutionComplete"]
