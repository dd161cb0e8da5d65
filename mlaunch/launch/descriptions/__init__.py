"""``launch.descriptions``: descriptions of what an action runs (``Executable``)."""

from mlaunch.launch.descriptions.executable import Executable

__all__ = ["Executable"]
