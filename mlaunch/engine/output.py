"""The one printer: what mlaunch says about a run, and each process's lines, to screen and logs.

Child output is data, never markup: bytes in, invalid UTF-8 replaced, each line prefixed with its
process label, written with one call per chunk. A chunk is prefixed with a single
``bytes.replace`` instead of a per-line Python loop, which is what lets mlaunch pass hundreds of
thousands of lines a second while the children keep running. Where the bytes go is not decided
here: the terminal is a Screen (mlaunch.engine.screen: non-blocking, bounded, flow-controlled by the
supervisor's loop) and the files are LogFiles (mlaunch.engine.logfiles). rich is used only by the
status view, and imported only when it is shown.
"""

from __future__ import annotations

import os
import re
import sys
import time
from collections.abc import Callable, Mapping

from mlaunch.engine.logfiles import (
    DEFAULT_ROTATE_BYTES,
    DEFAULT_ROTATE_KEEP,
    LogFile,
    log_file_name,
    tail_lines,
)
from mlaunch.engine.sayings import Sayings
from mlaunch.engine.screen import Screen
from mlaunch.plan.records import Output, Record, Summary

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.plan.records import ProcessView

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

# mlaunch's own levels by severity, with rcutils' names for them (--log-level).
OWN_LEVELS = {"DEBUG": 0, "INFO": 1, "WARN": 2, "WARNING": 2, "ERROR": 3, "FATAL": 4}
LEVEL_COLORS = {"INFO": b"", "WARNING": b"\x1b[33m", "ERROR": b"\x1b[31m", "DEBUG": b"\x1b[2m"}
LABEL_COLORS = [b"\x1b[32m", b"\x1b[36m", b"\x1b[35m", b"\x1b[34m", b"\x1b[33m", b"\x1b[92m",
                b"\x1b[96m", b"\x1b[95m", b"\x1b[94m", b"\x1b[93m"]  # fmt: skip
RESET = b"\x1b[0m"


def clean(data: bytes) -> bytes:
    """Valid UTF-8, with U+FFFD for whatever was not."""
    if data.isascii():
        return data  # the common case, checked without building a str
    try:
        data.decode("utf-8")
        return data
    except UnicodeDecodeError:
        return data.decode("utf-8", "replace").encode("utf-8")


# The level of a ROS log line, where a line starts with one: rcutils/rclpy's ``[INFO] [stamp]
# [node]: ...`` (in colour when the child writes to a terminal) and roslaunch's ``[ INFO] ...``.
# Compiled on first use (only ``-q`` reads levels): ~0.4 ms off every start.
ROS_LOG_LEVEL_PATTERN = rb"^(?:\x1b\[[0-9;]*m)?\[ ?(DEBUG|INFO|WARN|WARNING|ERROR|FATAL)\]"
QUIET_LEVELS = frozenset({b"WARN", b"WARNING", b"ERROR", b"FATAL"})


def quiet_lines(stream: str, data: bytes) -> bytes:
    """The lines ``-q`` shows of a chunk: ROS log lines at WARN and above, from either stream,
    and the stderr lines that are not ROS log lines (a traceback, a program's own complaint)."""
    level_of = re.compile(ROS_LOG_LEVEL_PATTERN, re.MULTILINE)  # from re's cache after the first
    if level_of.search(data) is None:
        return data if stream == "stderr" else b""  # the common case, without a line loop
    kept = []
    for line in data.splitlines(keepends=True):
        level = level_of.match(line)
        if level is None:
            if stream == "stderr":
                kept.append(line)
        elif level.group(1) in QUIET_LEVELS:
            kept.append(line)
    return b"".join(kept)


def prefix_lines(prefix: bytes, data: bytes) -> bytes:
    """Each line of ``data`` (complete lines, ending in newline) with ``prefix`` before it."""
    return prefix + data[:-1].replace(b"\n", b"\n" + prefix) + b"\n"


class Printer:
    """Owns the terminal and the log files of a run: every byte mlaunch writes goes here.

    A Printer is a subscriber of the supervisor's RecordStream (``__call__``): a process's output
    and the exit summary are its own (``_SAYS`` at the end of this module), every other record
    its ``sayings`` put in words (mlaunch.engine.sayings).

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
        level: str | None = None,
    ) -> None:
        self.out = out
        self.color = color
        self.log_dir = log_dir
        self.rotate_bytes = rotate_bytes
        self.rotate_keep = rotate_keep
        self.quiet = quiet
        self.clock = clock
        # The least severe of mlaunch's own lines shown (--log-level; -q is WARNING).
        self._rank = OWN_LEVELS.get((level or "").upper(), 2 if quiet else 1)
        # The Screen under whatever the screen output goes through (a status view wraps it).
        self._screen: Screen | None
        self._write: Callable[[bytes], object]
        if out is None:
            self._screen = self._write = Screen()
        else:
            self._screen = out if isinstance(out, Screen) else None
            self._write = out
        self._launch_log: LogFile | None = None
        # launch.log stops copying process lines past rotate_bytes (they stay in <label>.log);
        # mlaunch's own messages always go in, so launch.log never rotates and loses none.
        self._launch_log_full = False
        self._own: dict[str, LogFile] = {}
        self._prefix: dict[str, bytes] = {}
        # Labels whose output the user muted (``mute``): kept off the screen only.
        self._muted: set[str] = set()
        self._dirty: set[LogFile] = set()
        self._log_errors: list[str] = []
        # label -> the start of its stdout lines that mlaunch says itself (ProcessSpec.announce)
        self._announcing: dict[str, bytes] = {}
        self.sayings = Sayings(self)
        if self.log_dir:
            self._launch_log = self._open("launch.log", lazy=False, rotate=False)

    def __repr__(self) -> str:
        return f"Printer(log_dir={self.log_dir!r}, color={self.color}, quiet={self.quiet})"

    def _open(self, name: str, *, lazy: bool = True, rotate: bool = True) -> LogFile:
        assert self.log_dir is not None
        return LogFile(
            os.path.join(self.log_dir, name),
            rotate_bytes=self.rotate_bytes if rotate else 0,
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

    def holding(self, label: str | None = None) -> bool:
        """The terminal is far behind (everyone's output, or ``label``'s own): stop reading the
        children (that one) until it catches up."""
        screen = self._screen
        return screen is not None and screen.holding(label)

    def flush_screen(self) -> None:
        """Hand the terminal what it takes now (its fd was reported writable)."""
        if self._screen is not None:
            self._screen.flush()

    # --- launch's own messages ----------------------------------------------------------------

    def message(self, level: str, source: str, text: str, *, always: bool = False) -> None:
        """``[LEVEL] [source]: text`` on screen and in launch.log (``always``: under -q too)."""
        line = f"[{level}] [{source}]: {text}\n".encode("utf-8", "replace")
        if always or OWN_LEVELS.get(level, 1) >= self._rank:
            write = getattr(self._write, "urgent", self._write)
            if self.color and LEVEL_COLORS.get(level):
                write(LEVEL_COLORS[level] + line[:-1] + RESET + b"\n")
            else:
                write(line)
        if self._launch_log is not None:
            self._launch_log.write(b"%.7f " % self.clock() + line)
            self._dirty.add(self._launch_log)

    def mute(self, label: str, muted: bool = True) -> None:
        """Keep ``label``'s output off the screen (its log file still gets every line), or
        show it again; at once, whoever asks (runtime control, from any loop callback)."""
        if muted:
            self._muted.add(label)
        else:
            self._muted.discard(label)

    def is_muted(self, label: str) -> bool:
        """Whether the user keeps ``label``'s output off the screen (its log still gets it)."""
        return label in self._muted

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
            self._own[label] = self._open(log_file_name(label))

    def output(self, label: str, stream: str, mode: str, data: bytes) -> None:
        """Complete lines from a process (bytes ending in newline)."""
        data = clean(data)
        # -q quiets mlaunch's own messages and the children's lines below WARN: their ROS log
        # lines by level, whatever the stream, and the rest of their stdout.
        if stream in SCREEN_STREAMS.get(mode, ()) and label not in self._muted:
            shown = quiet_lines(stream, data) if self.quiet else data
            if not shown:
                pass
            elif self._write is self._screen:
                # Counted per process, for per-process flow control (Screen.holding).
                self._screen.write(prefix_lines(self._prefix[label], shown), source=label)
            else:
                self._write(prefix_lines(self._prefix[label], shown))
        own = self._own.get(label)
        if own is not None:
            own.write(data)
            self._dirty.add(own)
        if self._launch_log is not None and mode in LAUNCH_LOG_MODES:
            self._copy_to_launch_log(label, data)

    def _copy_to_launch_log(self, label: str, data: bytes) -> None:
        """A process's lines into launch.log too, until it has ``rotate_bytes`` (then said once)."""
        log = self._launch_log
        assert log is not None
        if self._launch_log_full:
            return
        lines = prefix_lines(b"%.7f [%s] " % (self.clock(), label.encode()), data)
        room = self.rotate_bytes - log.size
        if not self.rotate_bytes or len(lines) <= room:
            log.write(lines)
        else:
            log.write(lines[: lines.rfind(b"\n", 0, max(0, room)) + 1])  # whole lines that fit
            self._launch_log_full = True
            note = (
                f"[INFO] [launch]: launch.log has reached {self.rotate_bytes} bytes: from here on"
                " it keeps mlaunch's own messages only; each process's lines stay in its"
                " <label>.log\n"
            )
            log.write(b"%.7f " % self.clock() + note.encode())
        self._dirty.add(log)

    def log_tail(self, label: str, count: int) -> list[bytes] | None:
        """The last ``count`` lines ``label`` wrote (from its log file); None without log files."""
        own = self._own.get(label)
        if own is None:
            if not self.log_dir:
                return None
            return tail_lines(os.path.join(self.log_dir, log_file_name(label)), count)
        own.flush()
        return tail_lines(own.path, count)

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

    # --- the run's events, in words -------------------------------------------------------------

    def __call__(self, record: Record) -> None:
        """The printer's subscription to the supervisor's RecordStream: each record in words."""
        method = _SAYS.get(type(record))
        if method is not None:
            method(self, record)
        else:
            self.sayings(record)

    def say_lines_of(self, label: str, start: bytes) -> None:
        """``label``'s stdout lines that begin with ``start`` are said whatever its output mode."""
        self._announcing[label] = start

    def _summary(self, event: Summary) -> None:
        self.block(event.text)

    def _output(self, event: Output) -> None:
        process = event.process
        start = self._announcing.get(process.label) if self._announcing else None
        if start is not None and event.stream == "stdout" and start in event.data:
            self._announced_output(process, event.data, start)
        else:
            self.output(process.label, event.stream, process.spec.output, event.data)

    def _announced_output(self, process: ProcessView, data: bytes, start: bytes) -> None:
        """A process's stdout with lines that say where to reach it, which mlaunch says itself.

        Such a line (the address of a stand-in's page) must be seen whatever the output mode
        (``log`` hides its stdout) and under -q, and only once: the child's copy goes to its own
        log file.
        """
        label, mode = process.label, process.spec.output
        rest = b""
        for line in data.splitlines(keepends=True):
            if not line.startswith(start):
                rest += line
                continue
            if rest:
                self.output(label, "stdout", mode, rest)
                rest = b""
            self.message("INFO", label, clean(line).decode().rstrip(), always=True)
            own = self._own.get(label)
            if own is not None:
                own.write(line)
                self._dirty.add(own)
        if rest:
            self.output(label, "stdout", mode, rest)


def stdout_is_color_terminal(environ: Mapping[str, str]) -> bool:
    if environ.get("NO_COLOR"):
        return False
    if environ.get("FORCE_COLOR") or environ.get("RCUTILS_COLORIZED_OUTPUT") == "1":
        return True
    return sys.stdout.isatty() and environ.get("TERM") != "dumb"


# Which words each record of the record stream becomes (records not listed are not said): a
# process's output here, everything else mlaunch.engine.sayings'.
_SAYS: dict[type, Callable[[Printer, Any], None]] = {
    Output: Printer._output,
    Summary: Printer._summary,
}
