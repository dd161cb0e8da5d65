"""``launch.events.matchers``, where upstream defines it."""

from mlaunch.launch.events import matches_action

__all__ = ["matches_action"]
