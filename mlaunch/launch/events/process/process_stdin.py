"""``launch.events.process.process_stdin``, where upstream defines it."""

from mlaunch.launch.events.process import ProcessStdin

__all__ = ["ProcessStdin"]
