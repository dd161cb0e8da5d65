"""``launch_testing.event_handlers``: StdoutReadyListener."""

from __future__ import annotations

from mlaunch.launch_testing.event_handlers.stdout_ready_listener import StdoutReadyListener

__all__ = ["StdoutReadyListener"]
