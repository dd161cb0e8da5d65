"""The supervisor's signal handling: handlers only record, the loop acts (uvicorn's signal_queue).

Stop signals (SIGINT, SIGTERM, SIGHUP) and SIGCHLD are recorded in ``pending`` and wake the
loop's selector through ``signal.set_wakeup_fd``; whatever was installed before is put back
when the run ends, so an embedder keeps its own handlers.
"""

from __future__ import annotations

import os
import selectors
import signal

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class SignalWatch:
    """Records signals for one run's loop; ``install`` adds the stop signals to SIGCHLD."""

    def __init__(self, *, install: bool = True) -> None:
        self.install = install
        self.pending: list[int] = []
        # Off the main thread Python delivers no signals to us: no handlers, no SIGCHLD, so the
        # loop polls for exited children instead (a LaunchService run from a worker thread).
        self.polling = False
        self._wake_r = self._wake_w = -1
        self._old_wakeup = -1
        self._old_handlers: dict[int, Any] = {}
        self._old_mask: set[int | signal.Signals] | None = None

    def start(self, selector: selectors.BaseSelector) -> None:
        """Install the handlers; the wake-up pipe is read from ``selector``."""
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        try:
            # What was there before is put back at the end (an embedder may have its own).
            self._old_wakeup = signal.set_wakeup_fd(self._wake_w, warn_on_full_buffer=False)
        except ValueError:  # not the main thread (threading costs start-up time to ask)
            self.polling = True
            self._close_pipe()
            return
        selector.register(self._wake_r, selectors.EVENT_READ, self._drain_wakeup)
        ours = (*STOP_SIGNALS, signal.SIGCHLD) if self.install else (signal.SIGCHLD,)
        self._old_handlers = {sig: signal.signal(sig, self._record) for sig in ours}
        # mlaunch blocks the stop signals while it hands them over to us (lifeline): what
        # arrived in that window is delivered now, to these handlers. The mask is put back.
        self._old_mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, ours)

    def _record(self, signum: int, frame: object) -> None:
        self.pending.append(signum)

    def _drain_wakeup(self, fd: int) -> None:
        drain(fd)

    def stop(self) -> None:
        """Put back the mask, handlers and wake-up fd that were there before ``start``."""
        if self.polling:
            return
        if self._old_mask is not None:
            # Blocked again first, if they were: none may reach a handler that is not ours.
            signal.pthread_sigmask(signal.SIG_SETMASK, self._old_mask)
            self._old_mask = None
        for sig, handler in self._old_handlers.items():
            signal.signal(sig, handler if handler is not None else signal.SIG_DFL)
        signal.set_wakeup_fd(self._old_wakeup)
        self._close_pipe()

    def _close_pipe(self) -> None:
        for fd in (self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass


def drain(fd: int) -> None:
    """Read a non-blocking wake-up pipe empty (its bytes only say "look again")."""
    try:
        while os.read(fd, 4096):
            pass
    except BlockingIOError:
        pass
