"""The one printer: supervisor events -> terminal and log files.

Child output is data, never markup: bytes in, invalid UTF-8 replaced, each line prefixed with its
process label, written with one call per chunk. A chunk is prefixed with a single
``bytes.replace`` instead of a per-line Python loop, which is what lets mlaunch pass hundreds of
thousands of lines a second while the children keep running. The terminal never blocks the
supervisor (Screen: a bounded, non-blocking queue that the supervisor flushes whenever fd 1 is
writable); when the reader is slower than the children, the supervisor stops reading their pipes
until the queue drains, so they slow down to the reader's pace and no line is lost. Only a reader
that takes nothing at all for a while (a paused terminal) costs screen lines, counted and
reported; the log files get every line. rich is used only by the status view, and imported only
when it is shown.
"""

from __future__ import annotations

import os
import select
import stat
import sys
import time
from collections import deque
from collections.abc import Callable, Mapping

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import IO

# Which targets each output mode sends a stream to (ROS 2's table; "own" = the process's file,
# which mlaunch always writes so every process has its log).
SCREEN_STREAMS: dict[str, frozenset[str]] = {
    "log": frozenset({"stderr"}),
    "screen": frozenset({"stdout", "stderr"}),
    "both": frozenset({"stdout", "stderr"}),
    "own_log": frozenset(),
    "full": frozenset({"stdout", "stderr"}),
}
LAUNCH_LOG_MODES = frozenset({"log", "both", "full"})

LEVEL_COLORS = {"INFO": b"", "WARNING": b"\x1b[33m", "ERROR": b"\x1b[31m", "DEBUG": b"\x1b[2m"}
LABEL_COLORS = [b"\x1b[32m", b"\x1b[36m", b"\x1b[35m", b"\x1b[34m", b"\x1b[33m", b"\x1b[92m",
                b"\x1b[96m", b"\x1b[95m", b"\x1b[94m", b"\x1b[93m"]  # fmt: skip
RESET = b"\x1b[0m"

DEFAULT_ROTATE_BYTES = 64 * 1024 * 1024
DEFAULT_ROTATE_KEEP = 3
# Per log file: a hundred processes must not pin a hundred large buffers.
LOG_BUFFER = 64 * 1024
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


def clean(data: bytes) -> bytes:
    """Valid UTF-8, with U+FFFD for whatever was not."""
    if data.isascii():
        return data  # the common case, checked without building a str
    try:
        data.decode("utf-8")
        return data
    except UnicodeDecodeError:
        return data.decode("utf-8", "replace").encode("utf-8")


def prefix_lines(prefix: bytes, data: bytes) -> bytes:
    """Each line of ``data`` (complete lines, ending in newline) with ``prefix`` before it."""
    return prefix + data[:-1].replace(b"\n", b"\n" + prefix) + b"\n"


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


class LogFile:
    """An append-only log file that rotates at a size limit (name -> name.1 -> name.2 ...).

    It is opened on the first write (so starting a hundred processes does not first open a
    hundred files). A write error (disk full) stops this file, once, through ``on_error``;
    it never stops the run.
    """

    def __init__(
        self,
        path: str,
        *,
        rotate_bytes: int,
        keep: int,
        lazy: bool = False,
        on_error: Callable[[str, OSError], None] | None = None,
    ) -> None:
        self.path = path
        self.rotate_bytes = rotate_bytes
        self.keep = keep
        self.on_error = on_error
        self.error: OSError | None = None
        self.size = 0
        self._file: IO[bytes] | None = None
        if not lazy:
            self._open()

    def _open(self) -> None:
        self._file = open(self.path, "ab", buffering=LOG_BUFFER)  # noqa: SIM115
        self.size = self._file.tell()

    def write(self, data: bytes) -> None:
        if self.error is not None:
            return
        try:
            if self._file is None:
                self._open()
            limit = self.rotate_bytes
            while limit and self.size + len(data) > limit:
                # Fill this file up to the limit at a line boundary, then start the next one;
                # only a single line longer than the limit makes a file exceed it.
                cut = data.rfind(b"\n", 0, max(0, limit - self.size)) + 1
                if cut:
                    self._append(data[:cut])
                    data = data[cut:]
                if self.size:
                    self.rotate()
                elif not cut:
                    break
            if data:
                self._append(data)
        except OSError as e:
            self._failed(e)

    def _append(self, data: bytes) -> None:
        assert self._file is not None
        self._file.write(data)
        self.size += len(data)

    def _failed(self, error: OSError) -> None:
        self.error = error
        if self._file is not None:
            try:
                self._file.close()
            except OSError:
                pass  # the buffered rest cannot be written either
        if self.on_error is not None:
            self.on_error(self.path, error)

    def rotate(self) -> None:
        if self._file is not None:
            self._file.close()
        for i in range(self.keep - 1, 0, -1):
            older = f"{self.path}.{i}"
            if os.path.exists(older):
                os.replace(older, f"{self.path}.{i + 1}")
        if self.keep > 0:
            os.replace(self.path, f"{self.path}.1")
        else:
            os.unlink(self.path)
        self._open()
        self.size = 0

    def flush(self) -> None:
        if self._file is None or self.error is not None:
            return
        try:
            self._file.flush()
        except OSError as e:
            self._failed(e)

    def close(self) -> None:
        self.flush()
        if self._file is not None and self.error is None:
            self._file.close()


def log_base_dir(environ: Mapping[str, str]) -> str:
    """``$ROS_LOG_DIR``, else ``$ROS_HOME/log``, else ``~/.ros/log`` (as ROS 2)."""
    if environ.get("ROS_LOG_DIR"):
        base = environ["ROS_LOG_DIR"]
    elif environ.get("ROS_HOME"):
        base = os.path.join(environ["ROS_HOME"], "log")
    else:
        base = os.path.join(os.path.expanduser("~"), ".ros", "log")
    return os.path.normpath(os.path.expanduser(base))


def make_run_log_dir(environ: Mapping[str, str]) -> str:
    """Create ``<base>/<timestamp>-<host>-<pid>/`` and point ``<base>/latest`` at it."""
    base = log_base_dir(environ)
    stamp = time.strftime("%Y-%m-%d-%H-%M-%S", time.localtime())
    micro = f"{time.time() % 1:.6f}"[2:]
    path = os.path.join(base, f"{stamp}-{micro}-{os.uname().nodename}-{os.getpid()}")
    os.makedirs(path, exist_ok=True)
    latest = os.path.join(base, "latest")
    if not os.path.exists(latest) or os.path.islink(latest):
        tmp = f"{latest}.{os.getpid()}"
        try:
            os.symlink(os.path.basename(path), tmp)
            os.replace(tmp, latest)
        except OSError:
            pass
    return path


class Printer:
    """Owns the terminal and the log files of a run.

    ``out`` receives every byte meant for the screen; None means the real terminal through a
    Screen (non-blocking, bounded), whose flow control the supervisor drives (``waiting_fd``,
    ``holding``, ``flush_screen``). Tests pass a callable that collects bytes, or a Screen.
    """

    def __init__(
        self,
        out: Callable[[bytes], object] | None = None,
        color: bool = False,
        log_dir: str | None = None,
        rotate_bytes: int = DEFAULT_ROTATE_BYTES,
        rotate_keep: int = DEFAULT_ROTATE_KEEP,
        quiet: bool = False,
        clock: Callable[[], float] = time.time,
    ) -> None:
        self.out = out
        self.color = color
        self.log_dir = log_dir
        self.rotate_bytes = rotate_bytes
        self.rotate_keep = rotate_keep
        self.quiet = quiet
        self.clock = clock
        # The Screen under whatever the screen output goes through (a status view wraps it).
        self._screen: Screen | None
        self._write: Callable[[bytes], object]
        if out is None:
            self._screen = self._write = Screen()
        else:
            self._screen = out if isinstance(out, Screen) else None
            self._write = out
        self._launch_log: LogFile | None = None
        self._own: dict[str, LogFile] = {}
        self._prefix: dict[str, bytes] = {}
        self._dirty: set[LogFile] = set()
        self._log_errors: list[str] = []
        self.hooks: list[Callable[[str, str, bytes], None]] = []
        if self.log_dir:
            self._launch_log = self._open("launch.log", lazy=False)

    def __repr__(self) -> str:
        return f"Printer(log_dir={self.log_dir!r}, color={self.color}, quiet={self.quiet})"

    def _open(self, name: str, *, lazy: bool = True) -> LogFile:
        assert self.log_dir is not None
        return LogFile(
            os.path.join(self.log_dir, name),
            rotate_bytes=self.rotate_bytes,
            keep=self.rotate_keep,
            lazy=lazy,
            on_error=self._log_failed,
        )

    def _log_failed(self, path: str, error: OSError) -> None:
        # Said on screen only (the log is what failed), and only once per file.
        text = (
            f"[ERROR] [launch]: cannot write {path}: {error.strerror or error}; not logging to it"
        )
        self._write(text.encode("utf-8", "replace") + b"\n")

    # --- where screen output goes -------------------------------------------------------------

    @property
    def screen(self) -> Callable[[bytes], object]:
        return self._write

    def set_screen(self, out: Callable[[bytes], object]) -> Callable[[bytes], object]:
        """Send screen output to ``out`` from now on (the status view); returns the previous one."""
        previous, self._write = self._write, out
        return previous

    def blocked(self) -> bool:
        """The screen has output waiting for the terminal (the supervisor then polls)."""
        return bool(getattr(self._write, "blocked", False))

    # --- flow control, driven by the supervisor's loop ------------------------------------------

    def waiting_fd(self) -> int | None:
        """The terminal's fd while output waits for it (to select for writability), else None."""
        screen = self._screen
        if screen is None or not screen.waiting:
            return None
        return screen.fd

    def holding(self) -> bool:
        """The terminal is far behind: stop reading the children until it catches up."""
        screen = self._screen
        return screen is not None and screen.holding()

    def flush_screen(self) -> None:
        """Hand the terminal what it takes now (its fd was reported writable)."""
        if self._screen is not None:
            self._screen.flush()

    # --- launch's own messages ----------------------------------------------------------------

    def message(self, level: str, source: str, text: str) -> None:
        """``[LEVEL] [source]: text`` on screen and in launch.log."""
        line = f"[{level}] [{source}]: {text}\n".encode("utf-8", "replace")
        if not self.quiet or level in ("WARNING", "ERROR"):
            write = getattr(self._write, "urgent", self._write)
            if self.color and LEVEL_COLORS.get(level):
                write(LEVEL_COLORS[level] + line[:-1] + RESET + b"\n")
            else:
                write(line)
        if self._launch_log is not None:
            self._launch_log.write(b"%.7f " % self.clock() + line)
            self._dirty.add(self._launch_log)

    def block(self, text: str) -> None:
        """Lines of launch's own (the exit summary) as they are, on screen and in launch.log."""
        data = text.encode("utf-8", "replace")
        if not data.endswith(b"\n"):
            data += b"\n"
        self._write(data)
        if self._launch_log is not None:
            self._launch_log.write(data)
            self._dirty.add(self._launch_log)

    # --- process output ------------------------------------------------------------------------

    def register(self, label: str, index: int) -> None:
        """Prepare a process's prefix and log file (once; respawns reuse them)."""
        if label in self._prefix:
            return
        plain = f"[{label}] ".encode()
        if self.color:
            color = LABEL_COLORS[index % len(LABEL_COLORS)]
            self._prefix[label] = color + plain[:-1] + RESET + b" "
        else:
            self._prefix[label] = plain
        if self.log_dir:
            self._own[label] = self._open(f"{label}.log")

    def output(self, label: str, stream: str, mode: str, data: bytes) -> None:
        """Complete lines from a process (bytes ending in newline)."""
        data = clean(data)
        if stream in SCREEN_STREAMS.get(mode, ()) and not self.quiet:
            self._write(prefix_lines(self._prefix[label], data))
        own = self._own.get(label)
        if own is not None:
            own.write(data)
            self._dirty.add(own)
        if self._launch_log is not None and mode in LAUNCH_LOG_MODES:
            self._launch_log.write(
                prefix_lines(b"%.7f [%s] " % (self.clock(), label.encode()), data)
            )
            self._dirty.add(self._launch_log)
        for hook in self.hooks:
            hook(label, stream, data)

    def flush(self) -> None:
        """Push buffered lines to disk and screen (called when the supervisor is about to wait)."""
        if self._dirty:
            for f in self._dirty:
                f.flush()
            self._dirty.clear()
        flush = getattr(self._write, "flush", None)
        if flush is not None:
            flush()

    def close(self) -> None:
        self.flush()
        if self._launch_log is not None:
            self._launch_log.close()
        for f in self._own.values():
            f.close()
        close = getattr(self._write, "close", None)
        if close is not None:
            close()


def stdout_is_color_terminal(environ: Mapping[str, str]) -> bool:
    if environ.get("NO_COLOR"):
        return False
    if environ.get("FORCE_COLOR") or environ.get("RCUTILS_COLORIZED_OUTPUT") == "1":
        return True
    return sys.stdout.isatty() and environ.get("TERM") != "dumb"
