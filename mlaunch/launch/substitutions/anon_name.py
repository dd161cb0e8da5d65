"""``launch.substitutions.anon_name``, where upstream defines it."""

from mlaunch.launch.substitutions import AnonName

__all__ = ["AnonName"]
