"""``launch.actions.emit_event``, where upstream defines it."""

from mlaunch.launch.actions import EmitEvent

__all__ = ["EmitEvent"]
