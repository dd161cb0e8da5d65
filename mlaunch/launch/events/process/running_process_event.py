"""``launch.events.process.running_process_event``, where upstream defines it."""

from mlaunch.launch.events.process import RunningProcessEvent

__all__ = ["RunningProcessEvent"]
