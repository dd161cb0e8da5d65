"""``launch.events.process.process_io``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessIO

__all__ = ["ProcessIO"]
