"""``launch.events.process.process_targeted_event``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessTargetedEvent

__all__ = ["ProcessTargetedEvent"]
