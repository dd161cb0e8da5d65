"""``launch.events.process.process_matchers``, where upstream defines it."""

from mlaunch.launch.events.process import matches_executable, matches_name, matches_pid

__all__ = ["matches_executable", "matches_name", "matches_pid"]
