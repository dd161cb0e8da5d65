"""``launch.events.process.process_stderr``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessStderr

__all__ = ["ProcessStderr"]
