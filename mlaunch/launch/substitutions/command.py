"""``launch.substitutions.command``, where upstream defines it."""

from mlaunch.launch.substitutions import Command

__all__ = ["Command"]
