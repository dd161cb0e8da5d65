"""``launch.events.process.process_exited``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessExited

__all__ = ["ProcessExited"]
