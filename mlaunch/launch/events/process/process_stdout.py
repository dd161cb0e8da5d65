"""``launch.events.process.process_stdout``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessStdout

__all__ = ["ProcessStdout"]
