"""``launch.events.process.process_started``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessStarted

__all__ = ["ProcessStarted"]
