"""``MessagePump``: spin a node's callbacks in a thread, so tests do not have to."""

from __future__ import annotations

import threading

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# How long one spin waits for work: also how long stop() may take to be noticed.
SPIN_PERIOD = 1.0
STOP_TIMEOUT = 5.0


class MessagePump:
    """Runs ``node``'s callbacks on an executor of ``context`` in a thread, from ``start()``
    until ``stop()``."""

    def __init__(self, node: Any, context: Any = None) -> None:
        self._node = node
        self._context = context
        self._running = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="msg_pump_thread")

    def start(self) -> None:
        self._running.set()
        self._thread.start()

    def stop(self) -> None:
        """Stop spinning and wait for the thread; an Exception when it does not end in time."""
        self._running.clear()
        self._thread.join(timeout=STOP_TIMEOUT)
        if self._thread.is_alive():
            raise Exception("Timed out waiting for message pump to stop")

    def _spin(self) -> None:
        from rclpy.executors import SingleThreadedExecutor

        executor = SingleThreadedExecutor(context=self._context)
        executor.add_node(self._node)
        while self._running.is_set():
            executor.spin_once(timeout_sec=SPIN_PERIOD)


__all__ = ["MessagePump"]
