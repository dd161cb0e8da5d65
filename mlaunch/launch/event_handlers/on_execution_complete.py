"""``launch.event_handlers.on_execution_complete``, where upstream defines it."""

from mlaunch.launch.event_handlers import OnExecutionComplete

__all__ = ["OnExecutionComplete"]
