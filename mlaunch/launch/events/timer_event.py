"""``launch.events.timer_event``, where upstream defines it."""

from mlaunch.launch.events import TimerEvent

__all__ = ["TimerEvent"]
