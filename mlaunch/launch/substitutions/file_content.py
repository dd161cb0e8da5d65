"""``launch.substitutions.file_content``, where upstream defines it."""

from mlaunch.launch.substitutions import FileContent

__all__ = ["FileContent"]
