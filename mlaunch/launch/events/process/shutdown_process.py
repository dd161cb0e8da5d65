"""``launch.events.process.shutdown_process``, where upstream defines it."""

from mlaunch.launch.events.process import ShutdownProcess

__all__ = ["ShutdownProcess"]
