"""The terminal (fd 1), which the supervisor must never block on: a queue with flow control.

The Printer decides what is said; this module decides when the terminal takes it. Output is
queued and written without blocking whenever fd 1 is writable (the supervisor's loop selects on
it); above a high-water mark the supervisor stops reading its children's pipes until the queue
drains, so a slow reader slows the children down and no line is lost. Only a reader that takes
nothing at all for a while (a paused terminal) costs screen lines, counted and reported; the log
files (mlaunch.engine.logfiles) get every line.
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
# Per process: above SOURCE_HIGH_WATER queued bytes of its own, that one process is not read
# until it is below SOURCE_LOW_WATER. A flooding child waits for the reader; the others are
# still read, and their lines queue behind at most this much of the flood (head-of-line).
SOURCE_HIGH_WATER = 32 * 1024
SOURCE_LOW_WATER = 8 * 1024


class Screen:
    """The terminal (fd 1) for a supervisor that must never block on it.

    Output is queued and handed to the fd without blocking: O_NONBLOCK is set only around the
    write, so the shell sharing the terminal never inherits it. The supervisor flushes whenever
    the fd is writable (``waiting``/``fd``) and stops reading its children while ``holding()``:
    from ``high_water`` queued bytes until the queue is below ``low_water``. So a slow reader
    (a slow ssh link, ``| less``) slows the children down and loses nothing.

    Flow control is per process too: output written with a ``source`` (the process's label) is
    counted per source, and ``holding(source)`` holds a process with ``source_high_water`` bytes
    queued until it is down to ``source_low_water``. One flooding child is then throttled to
    the reader's pace while the quiet ones are still read, their lines behind at most that much
    of the flood instead of the whole backlog. The queue stays one FIFO, so every line keeps
    its place relative to mlaunch's messages about its process.

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
        source_high_water: int = SOURCE_HIGH_WATER,
        source_low_water: int = SOURCE_LOW_WATER,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.fd = fd
        self.limit = limit
        self.stall = stall
        # A small limit (a test's) scales the marks down, so that holding starts before dropping.
        self.high_water = min(high_water, max(1, limit // 2))
        self.low_water = min(low_water, self.high_water // 4)
        self.source_high_water = min(source_high_water, max(1, self.high_water // 4))
        self.source_low_water = min(source_low_water, self.source_high_water // 4)
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
        # Per source: bytes queued, and who wrote the queue's bytes, in order ((source, bytes)).
        self._by_source: dict[str, int] = {}
        self._owners: deque[tuple[str | None, int]] = deque()
        self._held_sources: set[str] = set()
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

    def write(self, data: bytes, *, urgent: bool = False, source: str | None = None) -> None:
        """Queue ``data`` (from process ``source``, if given); beyond the limit it is dropped
        (counted) unless ``urgent``."""
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
        self._append(data, source)
        if self._size >= SCREEN_CHUNK:
            self.flush()

    def _append(self, data: bytes, source: str | None = None) -> None:
        self._queue.append(data)
        self._size += len(data)
        if self._size > self.peak:
            self.peak = self._size
        owners = self._owners
        if owners and owners[-1][0] == source:
            owners[-1] = (source, owners[-1][1] + len(data))
        else:
            owners.append((source, len(data)))
        if source is not None:
            self._by_source[source] = self._by_source.get(source, 0) + len(data)

    def _taken(self, n: int) -> None:
        """The reader took the queue's first ``n`` bytes: count them off their sources."""
        owners, by_source = self._owners, self._by_source
        while n and owners:
            source, size = owners[0]
            take = min(n, size)
            n -= take
            if source is not None:
                left = by_source[source] - take
                if left:
                    by_source[source] = left
                else:
                    del by_source[source]
            if take < size:
                owners[0] = (source, size - take)
            else:
                owners.popleft()

    def queued(self, source: str) -> int:
        """Bytes of ``source`` waiting for the terminal."""
        return self._by_source.get(source, 0)

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

    def holding(self, source: str | None = None) -> bool:
        """Whether the producers (or process ``source``) should wait for the reader.

        Everyone from ``high_water`` queued bytes until below ``low_water``; one source from
        ``source_high_water`` of its own until below ``source_low_water``. Nobody once the
        reader has stalled.
        """
        if self._held:
            if self._size < self.low_water or self.gone:
                self._held = False
            else:
                return not self.stalled()
        elif self._size >= self.high_water and not self.gone:
            self._held = True
            return not self.stalled()
        if source is None or self.gone:
            return False
        queued = self._by_source.get(source, 0)
        if source in self._held_sources:
            if queued < self.source_low_water:
                self._held_sources.discard(source)
                return False
        elif queued < self.source_high_water:
            return False
        else:
            self._held_sources.add(source)
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
                self._owners.clear()
                self._by_source.clear()
                self._size = self._offset = 0
                return
            if n > 0:
                self._progress_at = self.clock()
                self._taken(n)
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
