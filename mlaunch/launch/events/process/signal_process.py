"""``launch.events.process.signal_process``, where upstream defines it."""

from mlaunch.launch.events.process import SignalProcess

__all__ = ["SignalProcess"]
