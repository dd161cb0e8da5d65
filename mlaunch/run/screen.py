"""The terminal (fd 1), which the supervisor must never block on: a queue with flow control.

The Printer decides what is said; this module decides when the terminal takes it. Output is
queued and written without blocking whenever fd 1 is writable (the supervisor's loop selects on
it); above a high-water mark the supervisor stops reading its children's pipes until the queue
drains, so a slow reader slows the children down and no line is lost. Only a reader that takes
nothing at all for a while (a paused terminal) costs screen lines, counted and reported; the log
files (mlaunch.run.logfiles) get every line.
"""

from __future__ import annotations

import os
import select
import stat
import time
from collections import deque
from collections.abc import Callable

# Screen output queued for a terminal that is behind, at most; beyond it lines are dropped
# from the screen (never from the logs). Only reached when the reader has stalled (below).
SCREEN_BACKLOG = 4 * 1024 * 1024
# Above HIGH_WATER queued bytes the supervisor stops reading the children's pipes, until the
# queue is below LOW_WATER again: the children wait for the reader instead of losing lines.
HIGH_WATER = 1024 * 1024
LOW_WATER = 256 * 1024
# A reader that takes nothing for this long (Ctrl-S, a pipe nobody reads) holds the children
# no longer: they run on, and what does not fit the backlog is dropped from the screen.
STALL = 1.0
# Queued screen output is written once this much has gathered, else when the loop goes idle.
SCREEN_CHUNK = 256 * 1024


class Screen:
    """The terminal (fd 1) for a supervisor that must never block on it.

    Output is queued and handed to the fd without blocking: O_NONBLOCK is set only around the
    write, so the shell sharing the terminal never inherits it. The supervisor flushes whenever
    the fd is writable (``waiting``/``fd``) and stops reading its children while ``holding()``:
    from ``high_water`` queued bytes until the queue is below ``low_water``. So a slow reader
    (a slow ssh link, ``| less``) slows the children down and loses nothing.

    A reader that makes no progress at all for ``stall`` seconds (a terminal paused with
    Ctrl-S, a pipe nobody reads) holds nobody any longer: the queue grows to ``limit`` bytes and
    beyond that output is dropped from the screen only, counted, and reported where the gap is
    (or once the terminal catches up). The children keep running and the log files keep every
    line. mlaunch's own messages (``urgent``) are never dropped.
    """

    def __init__(
        self,
        fd: int = 1,
        *,
        limit: int = SCREEN_BACKLOG,
        stall: float = STALL,
        high_water: int = HIGH_WATER,
        low_water: int = LOW_WATER,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.fd = fd
        self.limit = limit
        self.stall = stall
        # A small limit (a test's) scales the marks down, so that holding starts before dropping.
        self.high_water = min(high_water, max(1, limit // 2))
        self.low_water = min(low_water, self.high_water // 4)
        self.clock = clock
        # Totals over the run; the notices say what was dropped since the previous notice.
        self.dropped_lines = 0
        self.dropped_bytes = 0
        self._noted_lines = 0
        self._noted_bytes = 0
        self.peak = 0  # the most bytes ever queued (memory stays bounded: tests look)
        self.gone = False  # the reader went away (EPIPE, EIO): the screen is dropped for good
        self._queue: deque[bytes] = deque()
        self._offset = 0  # bytes of the queue's head already written
        self._size = 0
        self._held = False
        self._progress_at = 0.0  # the last write the reader took, or when output began waiting
        try:
            self._regular = stat.S_ISREG(os.fstat(fd).st_mode)
        except OSError:
            self._regular = False

    def __call__(self, data: bytes) -> None:
        self.write(data)

    @property
    def backlog(self) -> int:
        """Bytes queued for the terminal."""
        return self._size

    def write(self, data: bytes, *, urgent: bool = False) -> None:
        """Queue ``data``; beyond the limit it is dropped (counted) unless ``urgent``."""
        if self.gone:
            return
        if self._size + len(data) > self.limit and not urgent:
            self.dropped_lines += data.count(b"\n")
            self.dropped_bytes += len(data)
            return
        if not self._queue:
            self._progress_at = self.clock()  # the stall clock starts when output waits
        if self.dropped_bytes != self._noted_bytes and not urgent:
            # Room again after a gap: say so right where the lines are missing.
            self._append(self._drop_notice())
        self._append(data)
        if self._size >= SCREEN_CHUNK:
            self.flush()

    def _append(self, data: bytes) -> None:
        self._queue.append(data)
        self._size += len(data)
        if self._size > self.peak:
            self.peak = self._size

    def urgent(self, data: bytes) -> None:
        """mlaunch's own messages (an exit, an escalation) are few and small: never dropped."""
        self.write(data, urgent=True)

    @property
    def blocked(self) -> bool:
        """Output is waiting for the terminal."""
        return bool(self._queue) and not self.gone

    waiting = blocked

    def stalled(self) -> bool:
        """Output waits and the reader has taken nothing for ``stall`` seconds."""
        return self.blocked and self.clock() - self._progress_at >= self.stall

    def holding(self) -> bool:
        """Whether the producers should wait for the reader (the supervisor asks before reads).

        From ``high_water`` queued bytes until below ``low_water``, unless the reader stalled.
        """
        if self._held:
            if self._size < self.low_water or self.gone:
                self._held = False
                return False
        elif self._size < self.high_water or self.gone:
            return False
        else:
            self._held = True
        return not self.stalled()

    def flush(self) -> None:
        """Write what the terminal takes now; keep the rest queued."""
        if not self._queue or self.gone:
            return
        nonblocking = not self._regular and os.get_blocking(self.fd)
        if nonblocking:
            os.set_blocking(self.fd, False)
        try:
            self._write_queue()
            if not self._queue and self.dropped_bytes != self._noted_bytes:
                self._append(self._drop_notice())
                self._write_queue()
        finally:
            if nonblocking:
                try:
                    os.set_blocking(self.fd, True)
                except OSError:
                    pass

    def _write_queue(self) -> None:
        queue = self._queue
        while queue:
            if len(queue) > 1 and len(queue[0]) - self._offset < SCREEN_CHUNK:
                # Many small pieces (one per line burst) go out in one write.
                parts, size = [], 0
                while queue and size < SCREEN_CHUNK:
                    part = queue.popleft()
                    if self._offset:
                        part, self._offset = part[self._offset :], 0
                    size += len(part)
                    parts.append(part)
                queue.appendleft(b"".join(parts))
            head = queue[0]
            try:
                # A partial write keeps an offset into the head: the rest is never copied.
                n = os.write(self.fd, memoryview(head)[self._offset :] if self._offset else head)
            except BlockingIOError:
                return
            except OSError:
                self.gone = True
                queue.clear()
                self._size = self._offset = 0
                return
            if n > 0:
                self._progress_at = self.clock()
            self._size -= n
            self._offset += n
            if self._offset < len(head):
                return
            queue.popleft()
            self._offset = 0

    def _drop_notice(self) -> bytes:
        lines = self.dropped_lines - self._noted_lines
        size = self.dropped_bytes - self._noted_bytes
        self._noted_lines, self._noted_bytes = self.dropped_lines, self.dropped_bytes
        return (
            f"[WARNING] [launch]: the terminal fell behind: {lines} lines ({size / 1e6:.1f} MB)"
            " were not shown; the log files have them\n"
        ).encode()

    def close(self, timeout: float = 2.0) -> None:
        """Give the terminal up to ``timeout`` seconds to take what is still queued."""
        deadline = time.monotonic() + timeout
        self.flush()
        while self.blocked:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            select.select([], [self.fd], [], left)
            self.flush()
