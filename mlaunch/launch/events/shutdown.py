"""``launch.events.shutdown``, where upstream defines it."""

from mlaunch.launch.events import Shutdown

__all__ = ["Shutdown"]
