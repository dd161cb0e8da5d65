"""``launch.substitutions.find_executable``, where upstream defines it."""

from mlaunch.launch.substitutions import FindExecutable

__all__ = ["FindExecutable"]
