"""The children's pipes and the terminal in the supervisor's selector: reading with flow control.

While the terminal has a backlog, its fd is in the selector for writability, so the backlog is
written as fast as the reader takes it; while the backlog is above its high-water mark
(``Printer.holding()``), a child's pipe that becomes readable is taken out of the selector until
the terminal catches up, so the children block on their own pipes instead of losing lines. The
same holds per process: a child with more than its share queued (``Printer.holding(label)``,
32 KiB) is not read until the terminal has taken most of it, while the others are still read,
so one flooding child cannot stall every other child's lines. A reader that has stalled
(nothing taken for ~1 s) holds nobody: the Screen drops, and says so.
"""

from __future__ import annotations

import selectors
from collections.abc import Callable

from mlaunch.engine.output import Printer
from mlaunch.engine.process import Process


class Pipes:
    """Reads every child's pipes for one loop and hands complete lines to ``deliver``.

    ``deliver(process, stream, data)``: ``stream`` is ``"stdout"`` or ``"stderr"``, ``data``
    complete lines (bytes ending in a newline).
    """

    def __init__(
        self,
        selector: selectors.BaseSelector,
        printer: Printer,
        deliver: Callable[[Process, str, bytes], None],
    ) -> None:
        self.selector = selector
        self.printer = printer
        self.deliver = deliver
        # The terminal fd selected for writability, the fds that cannot be selected, and the
        # pipes not read while the terminal is behind (fd -> process).
        self._out_fd: int | None = None
        self._out_unselectable: set[int] = set()
        self.paused: dict[int, Process] = {}

    def watch(self, process: Process) -> None:
        """Read a just-started process's pipes from now on."""
        for fd in process.streams:
            self._select(process, fd)

    def before_wait(self) -> bool:
        """Select the terminal for writability while output waits; resume held pipes.

        True when the loop must poll: output waits on a terminal that cannot be selected on,
        or children wait for the terminal (a stalled reader must not hold them for longer
        than the Screen's stall time).
        """
        fd = self.printer.waiting_fd()
        if fd != self._out_fd:
            if self._out_fd is not None:
                self.selector.unregister(self._out_fd)
                self._out_fd = None
            if fd is not None and fd not in self._out_unselectable:
                try:
                    self.selector.register(fd, selectors.EVENT_WRITE, self._writable)
                    self._out_fd = fd
                except (OSError, ValueError, KeyError):
                    # A regular file or /dev/null (never blocks), a closed fd, or one already
                    # in the selector: flushed each turn instead.
                    self._out_unselectable.add(fd)
        if self.paused:
            self._resume_reading()
        if fd is None:
            # A screen of another kind (a test's) with a backlog.
            return self.printer.blocked() or bool(self.paused)
        return fd != self._out_fd or bool(self.paused)

    def forget_terminal(self) -> None:
        """The selector was closed with the terminal in it (the end of the run)."""
        self._out_fd = None

    def _writable(self, fd: int) -> None:
        self.printer.flush_screen()
        if self.paused:
            self._resume_reading()

    def _resume_reading(self) -> None:
        """Read the held pipes again whose process the terminal no longer holds (it caught up
        with everyone's output or with that process's, or it stalled)."""
        if self.printer.holding():
            return
        for fd, process in list(self.paused.items()):
            if self.printer.holding(process.label):
                continue
            del self.paused[fd]
            if fd in process.streams:
                self._select(process, fd)

    def _select(self, process: Process, fd: int) -> None:
        self.selector.register(
            fd, selectors.EVENT_READ, lambda fd, p=process: self._readable(p, fd)
        )

    def close(self, process: Process, fd: int) -> None:
        """Stop watching a pipe (in the selector, or held) and close it."""
        if self.paused.pop(fd, None) is None:
            self.selector.unregister(fd)
        process.close_stream(fd)

    def _readable(self, process: Process, fd: int) -> None:
        """A child's pipe has data: read it, unless the terminal is too far behind with
        everyone's output or with this process's own."""
        if self.printer.holding(process.label):
            # Leave it in the pipe: the child blocks on a full pipe until the terminal catches
            # up. Out of the selector meanwhile, or every turn would find it ready again.
            if fd in process.streams:
                self.selector.unregister(fd)
                self.paused[fd] = process
            return
        self.read(process, fd)

    def read(self, process: Process, fd: int) -> None:
        """Read what the pipe has now; close it at its end."""
        stream = process.streams.get(fd)
        if stream is None:
            return
        data, eof = process.read(fd)
        if data:
            self.deliver(process, stream.name, data)
        if eof:
            self.close(process, fd)

    def close_all(self, process: Process) -> None:
        """The end of the run: read what is left, then close every pipe of ``process``."""
        for fd in list(process.streams):
            self.read(process, fd)
            if fd in process.streams:
                self.close(process, fd)

    def drain(self, process: Process) -> None:
        """Read what is left in a finished process's pipes, then its partial last line.

        A child that died mid-line gets what it had printed (a grandchild may keep the pipe
        open, so the pipes are read a bounded number of times, not to their end).
        """
        for fd in list(process.streams):
            for _ in range(64):
                if fd not in process.streams:
                    break
                data, eof = process.read(fd)
                if data:
                    self.deliver(process, process.streams[fd].name, data)
                if eof:
                    self.close(process, fd)
        for stream in process.streams.values():
            if stream.partial:
                data, stream.partial = stream.partial + b"\n", b""
                self.deliver(process, stream.name, data)
