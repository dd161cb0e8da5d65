"""The terminal (fd 1), which the supervisor must never block on: a queue with flow control.

The Printer decides what is said; this module decides when the terminal takes it. Output is
queued and written without blocking whenever fd 1 is writable (the supervisor's loop selects on
it); above a high-water mark the supervisor stops reading its children's pipes until the queue
drains, so a slow reader slows the children down and no line is lost. A reader much slower than
that (a 30 KB/s link: ReaderPace measures it) costs a flooding process's excess screen lines
instead, so that nobody's line waits a second behind a flood; and a reader that takes nothing
at all for a while (a paused terminal) costs screen lines too. Both are counted and reported;
the log files (mlaunch.engine.logfiles) get every line.
"""

from __future__ import annotations

import math
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
# A slow but steady reader (a slow ssh link, a 30 KB/s serial console): once its pace is known,
# at most this many seconds of it wait in the kernel's buffer (a pipe holds 64 KiB: 2 s at
# 30 KB/s), and at most SOURCE_SECONDS of one process's output in the queue; the rest of that
# process's output is dropped from the screen (counted, said, kept in the logs), not held, so
# a quiet process's line waits well under a second behind a flood whatever the reader's pace.
KERNEL_SECONDS = 0.15
SOURCE_SECONDS = 0.25
PACE_WINDOW = 2.0  # seconds of the reader's recent progress its pace is measured over
MIN_AHEAD = 4096  # never pace below a page: a slow reader still gets whole lines
# Until the reader's pace is known (its first ~0.3 s of backlog), it may be a slow one: the
# kernel gets at most this much, and one process holds from UNKNOWN_SOURCE_HIGH queued bytes.
UNKNOWN_AHEAD = 8 * 1024
MAX_AHEAD = 1 << 20  # a reader that keeps up: no pacing to speak of
UNKNOWN_SOURCE_HIGH = 8 * 1024


class ReaderPace:
    """How fast the reader takes what is written to ``fd``, from the kernel's count of what it
    has not read yet (FIONREAD of a pipe, TIOCOUTQ of a terminal or socket).

    The pace (bytes/s) is measured only while the reader is the bottleneck: it took some and
    left the rest in the buffer. A reader that empties the buffer keeps up: the bytes allowed
    ahead of it double (``ahead``, from UNKNOWN_AHEAD) and its pace is unknown again. A stalled
    reader (nothing taken) changes neither: that is the Screen's ``stall``.
    """

    def __init__(self, fd: int, mode: int, clock: Callable[[], float]) -> None:
        import fcntl
        import termios

        self.fd, self.clock = fd, clock
        self._ioctl = fcntl.ioctl
        self._request = termios.FIONREAD if stat.S_ISFIFO(mode) else termios.TIOCOUTQ
        self.written = 0  # bytes handed to the fd
        self.ahead = UNKNOWN_AHEAD  # bytes the kernel may hold while the pace is unknown
        self.progress_at = -math.inf  # when the reader last took something
        self._taken = 0  # bytes the reader took (written - still in the kernel's buffer)
        self._since: float | None = None  # since when the reader has had data to read
        self._samples: deque[tuple[float, int]] = deque()  # (seconds, bytes) while saturated
        self._span = 0.0
        self._bytes = 0

    def wrote(self, n: int) -> None:
        """``n`` more bytes handed to the fd: the reader has something to read from now on."""
        self.written += n
        if self._since is None:
            self._since = self.clock()

    def unread(self) -> int | None:
        """Bytes in the kernel's buffer not yet read, or None when the fd cannot say."""
        buf = bytearray(4)
        try:
            self._ioctl(self.fd, self._request, buf)
        except OSError:
            return None
        return int.from_bytes(buf, "little")

    def sample(self) -> int | None:
        """Note the reader's progress now; the bytes still unread."""
        unread = self.unread()
        if unread is None:
            return None
        now, taken = self.clock(), self.written - unread
        if taken > self._taken:
            self.progress_at = now
            elapsed = 0.0 if self._since is None else now - self._since
            size = taken - self._taken
            if unread == 0 and size * KERNEL_SECONDS < self.ahead * elapsed:
                self._add(elapsed, size)  # it emptied the buffer, but slowly: a slow reader
                self._since = None
            elif unread == 0:  # it kept up with what it was given: give it more, pace unknown
                self.ahead = min(2 * self.ahead, MAX_AHEAD)
                self._samples.clear()
                self._span, self._bytes, self._since = 0.0, 0, None
            elif self._since is not None:
                self._add(now - self._since, taken - self._taken)
                self._since = now
            self._taken = taken
        return unread

    def blocked(self) -> None:
        """The fd took less than it was given (the kernel's count says the rest)."""

    def _add(self, seconds: float, size: int) -> None:
        self._samples.append((seconds, size))
        self._span += seconds
        self._bytes += size
        while self._span - self._samples[0][0] >= PACE_WINDOW:
            old_seconds, old_size = self._samples.popleft()
            self._span, self._bytes = self._span - old_seconds, self._bytes - old_size

    @property
    def rate(self) -> float | None:
        """Bytes per second, once 0.3 s of the reader being the bottleneck was seen."""
        return self._bytes / self._span if self._span >= 0.3 else None

    def room(self, unread: int) -> int:
        """Bytes the kernel's buffer may take now."""
        rate = self.rate
        ahead = self.ahead if rate is None else max(MIN_AHEAD, int(rate * KERNEL_SECONDS))
        return ahead - unread


# A pty (UNIX98 slaves: majors 136-143) says nothing of what it holds: TIOCOUTQ is always 0.
PTY_MAJORS = range(136, 144)
# While the reader's pace is measured from blocked writes: a window lasts at least this long...
WINDOW = 1.0
# ... and two blocked writes further apart than this are not one stretch of saturation.
SATURATED_GAP = 0.5
# A pace that held PROBE_AFTER seconds without the terminal blocking a write is raised by this
# factor (the reader may have sped up); past MAX_PACE it is a reader that keeps up. A raise
# that overshoots fills the terminal's buffer before it shows (a quiet line then waits ~0.7 s
# at 30 KB/s), so it is rare; a terminal left idle IDLE_RESET seconds is measured afresh.
PROBE_AFTER = 10.0
IDLE_RESET = 2.0
PROBE_FACTOR = 1.25
MEASURED_SHARE = 0.75
MAX_PACE = 1_000_000
# What a pty's buffer holds (Linux: ~20 KB), as the most a full one is assumed to hold.
PTY_BUFFER = 20 * 1024


class WritePace(ReaderPace):
    """The pace of a reader whose kernel buffer says nothing (a pty), from the time of writes.

    While the terminal blocks the writes (EAGAIN, a partial write), its buffer is full and it
    takes bytes as fast as the reader reads them: the pace is (a share of) the bytes it took
    between two blocked writes at least WINDOW apart. Until the first block it may keep up, and
    gets more each time it takes what it was given, as ReaderPace; while the pace is measured
    it gets what it takes (its buffer fills: ~20 KB, 0.7 s at 30 KB/s). A pace past MAX_PACE is
    a reader that keeps up (a terminal emulator: a pty's buffer is then a few ms of it). A slower
    one is paced: what the buffer holds is estimated (what was written, less the pace times the
    time since), and writes keep it near KERNEL_SECONDS of the pace, as ReaderPace does with the
    kernel's own count. A pace that held PROBE_AFTER seconds is raised a little, so that a
    reader that sped up is found: a write blocked after that raise goes back to the pace before
    it; one blocked otherwise means the reader slowed down, and its pace is measured afresh.
    """

    def __init__(self, fd: int, mode: int, clock: Callable[[], float]) -> None:
        super().__init__(fd, mode, clock)
        self._pace: float | None = None
        self._held = 0.0  # estimated bytes in the terminal's buffer, at ``_held_at``
        self._held_at = clock()
        self._window: tuple[float, int] | None = None  # (since, written then) while saturated
        self._blocked_at = -math.inf
        self._probed_at = -math.inf
        self._probing = False  # the pace was raised on trust and not blocked since
        self._fast = False  # measured faster than MAX_PACE: blocked writes are no sign of lag

    @property
    def rate(self) -> float | None:
        return self._pace

    def unread(self) -> int | None:
        now = self.clock()
        if self._pace is not None:
            self._held = max(0.0, self._held - self._pace * (now - self._held_at))
            if not self._held and now - self.progress_at >= IDLE_RESET:
                self._pace = None  # idle: the next burst measures the reader again
                self.ahead = UNKNOWN_AHEAD
            elif now - max(self._blocked_at, self._probed_at) >= PROBE_AFTER:
                self._probed_at = now
                self._probing = True
                self._pace *= PROBE_FACTOR
                if self._pace > MAX_PACE:  # keeps up: no pacing
                    self._pace = None
                    self._fast = True
                    self.ahead = MAX_AHEAD
        self._held_at = now
        return int(self._held)

    def sample(self) -> int | None:
        return self.unread()

    def room(self, unread: int) -> int:
        if self._pace is None:
            return 1 << 30  # as much as the terminal takes: that measures it
        return max(MIN_AHEAD, int(self._pace * KERNEL_SECONDS)) - unread

    def wrote(self, n: int) -> None:
        self.unread()  # the estimate up to now, before adding
        self.written += n
        self._held += n
        self.progress_at = now = self.clock()
        if self._pace is None and now - self._blocked_at > SATURATED_GAP:
            # It took what it was given (blocked() follows at once if not): give it more, as
            # ReaderPace does, so that a terminal that keeps up (MB/s) is soon not held at all.
            self.ahead = min(2 * self.ahead, MAX_AHEAD)

    def blocked(self) -> None:
        """The terminal took less than it was given: its buffer is full (a pty's holds ~20 KB,
        so a fast reader behind a faster child blocks writes too: the pace tells them apart)."""
        now = self.clock()
        if self._pace is not None and self._probing:
            # The last raise overshot: back to the pace before it, and the buffer is full.
            self._pace /= PROBE_FACTOR
            self._held = self._full()
            self._held_at = self._blocked_at = now
            self._probed_at = now
            self._probing = False
            return
        if self._pace is not None:  # the reader slowed down: measure it again
            self._pace = None
            self._window = None
        if not self._fast:
            self.ahead = UNKNOWN_AHEAD  # maybe a slow reader, until measured
        if self._window is None or now - self._blocked_at > SATURATED_GAP:
            self._window = (now, self.written)
        else:
            since, written = self._window
            if now - since >= WINDOW:
                # Measured as the kernel frees room, in its own steps: a window over-counts by
                # up to a fifth; a pace a little under the reader's keeps its buffer low.
                pace = MEASURED_SHARE * (self.written - written) / (now - since)
                self._fast = pace > MAX_PACE
                if self._fast:  # its ~20 KB are a few ms of it: no pacing
                    self.ahead = MAX_AHEAD
                elif pace > 0:
                    self._pace = pace
                    self._held = self._full()
                    self._held_at = now
                    self._probed_at = now
                self._window = None
        self._blocked_at = now

    def _full(self) -> float:
        """What a full pty holds, at most: ~0.6 s of the pace, and a pty takes ~20 KB."""
        assert self._pace is not None
        return min(self._pace * KERNEL_SECONDS * 4, PTY_BUFFER)


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
        self._pacing = False
        self._overflow: dict[str, bytes] = {}  # a process's lines read beyond its share
        self._noticed_at = -math.inf
        self._progress_at = 0.0  # the last write the reader took, or when output began waiting
        try:
            mode = os.fstat(fd).st_mode
        except OSError:
            mode = 0
        self._regular = stat.S_ISREG(mode)
        pace: ReaderPace | None = None
        if self._regular or not mode:
            pace = None
        elif stat.S_ISCHR(mode) and os.major(os.fstat(fd).st_rdev) in PTY_MAJORS:
            pace = WritePace(fd, mode, clock)
        else:
            pace = ReaderPace(fd, mode, clock)
        if pace is not None and pace.unread() is None:
            # A sink that cannot say what it holds: /dev/null (`>/dev/null`, `>&-`, systemd's
            # StandardOutput=null) discards at once, the fastest reader there is. Paced as an
            # unknown reader, it held every child to ~0.2 MB/s.
            pace = None
        self.pace = pace

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
        if source is None or urgent or self.pace is None:
            if self._overflow:  # mlaunch's word about a process comes after that one's lines
                self._spill()
            self._enqueue(data, urgent=urgent, source=source)
        else:
            self._admit(data, source)

    def _enqueue(self, data: bytes, *, urgent: bool = False, source: str | None = None) -> None:
        if self._size + len(data) > self.limit and not urgent:
            self._drop(data)
            return
        if not self._queue:
            self._progress_at = self.clock()  # the stall clock starts when output waits
        if self.dropped_bytes != self._noted_bytes and not urgent and self._notice_due():
            # Room again after a gap: say so right where the lines are missing.
            self._append(self._drop_notice())
        self._append(data, source)
        if self._size >= SCREEN_CHUNK:
            self.flush()

    def _drop(self, data: bytes) -> None:
        self.dropped_lines += data.count(b"\n")
        self.dropped_bytes += len(data)

    def _notice_due(self) -> bool:
        """A notice at most once a second: a flood dropped on a slow reader gaps every write."""
        return self.clock() - self._noticed_at >= 1.0

    def _marks(self) -> tuple[int, int, int | None]:
        """(hold mark, release mark, drop cap) of one process's queued bytes for this reader."""
        high, low = self.source_high_water, self.source_low_water
        if self.pace is None:  # a file, or an fd that cannot say: no pacing
            return high, low, None
        rate = self.pace.rate
        if rate is None and self.pace.ahead >= MAX_AHEAD:
            return high, low, None  # a reader that keeps up: the ordinary marks
        if rate is None:  # maybe a slow reader: hold early
            return min(high, UNKNOWN_SOURCE_HIGH), min(low, UNKNOWN_SOURCE_HIGH // 4), None
        cap = max(MIN_AHEAD, int(rate * SOURCE_SECONDS))
        return high, low, cap if cap < high else None

    def _admit(self, data: bytes, source: str) -> None:
        """Queue a process's lines up to its share; a slow reader's excess is dropped, else kept
        aside (in order) until the terminal has taken its queued lines. One read of a pipe can
        be 64 KiB: queued whole, a quiet process's line would wait behind all of it."""
        if source in self._overflow:
            self._overflow[source] += data
            return
        pace = self.pace
        if pace is not None and pace.rate is None and pace.ahead >= MAX_AHEAD:
            self._enqueue(data, source=source)  # a reader that keeps up: as it comes
            return
        queued = self.queued(source)
        high, _, cap = self._marks()
        head, rest = _split(data, (high if cap is None else cap) - queued, queued == 0)
        if head:
            self._enqueue(head, source=source)
        if rest and cap is not None:
            self._drop(rest)
        elif rest:
            self._overflow[source] = rest

    def _feed(self) -> None:
        """Queue what was kept aside of the processes whose queued lines the terminal took."""
        low = self._marks()[1]
        for source in [s for s in self._overflow if self.queued(s) < low]:
            self._admit(self._overflow.pop(source), source)

    def _spill(self, source: str | None = None) -> None:
        """Queue what was kept aside (of ``source``, or of everyone) as it is."""
        for name in [source] if source is not None else list(self._overflow):
            data = self._overflow.pop(name, None)
            if data:
                self._enqueue(data, source=name)

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
        return (bool(self._queue) or bool(self._overflow)) and not self.gone

    @property
    def waiting(self) -> bool:
        """Output waits and the terminal may take it when writable (not while pacing a slow
        reader: its fd is writable long before it should be written; the loop polls then)."""
        return self.blocked and not self._pacing

    def stalled(self) -> bool:
        """Output waits and the reader has taken nothing for ``stall`` seconds."""
        progress = self._progress_at
        if self.pace is not None:  # paced writes are rare: the reader's own progress counts
            progress = max(progress, self.pace.progress_at)
        return self.blocked and self.clock() - progress >= self.stall

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
        if source in self._overflow:
            self._feed()
            if source in self._overflow:
                if not self.stalled():
                    return True
                self._spill(source)  # a stalled reader holds nobody: the limit drops
        queued = self._by_source.get(source, 0)
        high, low, _ = self._marks()
        if source in self._held_sources:
            if queued < low:
                self._held_sources.discard(source)
                return False
        elif queued < high:
            return False
        else:
            self._held_sources.add(source)
        return not self.stalled()

    def flush(self) -> None:
        """Write what the terminal takes now; keep the rest queued."""
        if self._overflow and not self.gone:
            self._feed()
        if not self._queue or self.gone:
            return
        room = self._room()
        self._pacing = room is not None and room <= 0
        if self._pacing:
            return
        nonblocking = not self._regular and os.get_blocking(self.fd)
        if nonblocking:
            os.set_blocking(self.fd, False)
        try:
            self._write_queue(room)
            if not self._queue and self.dropped_bytes != self._noted_bytes:
                self._append(self._drop_notice())
                self._write_queue(room)
        finally:
            if nonblocking:
                try:
                    os.set_blocking(self.fd, True)
                except OSError:
                    pass

    def _room(self) -> int | None:
        """Bytes the kernel's buffer may take now (None: as much as it takes)."""
        if self.pace is None:
            return None
        unread = self.pace.sample()
        return None if unread is None else self.pace.room(unread)

    def _write_queue(self, room: int | None = None) -> None:
        queue = self._queue
        while queue and (room is None or room > 0):
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
            view = memoryview(head)[self._offset :] if self._offset else head
            if room is not None:
                view = memoryview(head)[self._offset : self._offset + room]
            try:
                # A partial write keeps an offset into the head: the rest is never copied.
                n = os.write(self.fd, view)
            except BlockingIOError:
                if self.pace is not None:
                    self.pace.blocked()
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
                if self.pace is not None:
                    self.pace.wrote(n)
                    if n < len(view):
                        self.pace.blocked()
                if room is not None:
                    room -= n
            self._size -= n
            self._offset += n
            if self._offset < len(head):
                return
            queue.popleft()
            self._offset = 0

    def _drop_notice(self) -> bytes:
        self._noticed_at = self.clock()
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
        self._spill()
        self.flush()
        while self.blocked:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            if self._pacing:  # writable long before it should be written: wait a moment
                time.sleep(min(left, 0.02))
            else:
                select.select([], [self.fd], [], left)
            self.flush()


def _split(data: bytes, size: int, first: bool) -> tuple[bytes, bytes]:
    """``data`` cut after its last whole line within ``size`` bytes (the first line at least
    when ``first``: a process with nothing queued always gets a line out)."""
    if len(data) <= size:
        return data, b""
    end = data.rfind(b"\n", 0, max(size, 0)) + 1
    if end == 0 and first:
        end = data.find(b"\n") + 1 or len(data)
    return data[:end], data[end:]
