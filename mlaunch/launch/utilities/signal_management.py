"""``AsyncSafeSignalManager``: signal handlers that run on an asyncio loop, as launch offers.

Built on ``signal.set_wakeup_fd``: while the manager's context is open, the C-level handler
writes each signal's number to a socket whose reader (on the loop) calls the handlers registered
for it. Handlers set with ``signal.signal`` still run; the wakeup descriptor that was installed
before (asyncio's own, an outer manager's) still gets every byte, so managers nest.
"""

from __future__ import annotations

import os
import signal
import socket
from collections.abc import Callable
from typing import Any

SignalHandler = Callable[[int], Any]


class AsyncSafeSignalManager:
    """A context manager in which handlers registered for a signal run on ``loop``."""

    def __init__(self, loop: Any) -> None:
        self._loop = loop
        self._handlers: dict[int, SignalHandler] = {}
        self._reader: socket.socket | None = None
        self._writer: socket.socket | None = None
        self._previous_fd = -1

    def __enter__(self) -> AsyncSafeSignalManager:
        reader, writer = socket.socketpair()
        reader.setblocking(False)
        writer.setblocking(False)
        self._reader, self._writer = reader, writer
        self._loop.add_reader(reader.fileno(), self._drain)
        try:
            self._previous_fd = signal.set_wakeup_fd(writer.fileno())
        except Exception:
            self._loop.remove_reader(reader.fileno())
            self._close()
            raise
        return self

    def __exit__(self, *exc_info: object) -> None:
        try:
            signal.set_wakeup_fd(self._previous_fd)
        finally:
            if self._reader is not None:
                self._loop.remove_reader(self._reader.fileno())
            self._close()

    def _close(self) -> None:
        for sock in (self._reader, self._writer):
            if sock is not None:
                sock.close()
        self._reader = self._writer = None

    def _drain(self) -> None:
        assert self._reader is not None
        try:
            data = self._reader.recv(4096)
        except (BlockingIOError, InterruptedError):
            return
        if self._previous_fd != -1:
            try:
                os.write(self._previous_fd, data)
            except OSError:
                pass  # the outer reader went away or is full: its signal is not ours to keep
        for signum in data:
            handler = self._handlers.get(signum)
            if handler is not None:
                handler(signum)

    def handle(self, signum: int | signal.Signals, handler: SignalHandler | None) -> Any:
        """Register ``handler`` for ``signum`` (None removes it); returns the previous one."""
        signum = signal.Signals(signum)
        previous = self._handlers.pop(signum, None)
        if handler is not None:
            if not callable(handler):
                raise ValueError(f"signal handler must be a callable, got {handler!r}")
            self._handlers[signum] = handler
        return previous
