"""``launch.event``, where upstream defines it."""

from mlaunch.launch.events import Event

__all__ = ["Event"]
