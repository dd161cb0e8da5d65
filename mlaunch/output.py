"""The one printer: supervisor events -> terminal and log files.

Child output is data, never markup: bytes in, invalid UTF-8 replaced, each line prefixed with its
process label, written with one call per chunk. A chunk is prefixed with a single
``bytes.replace`` instead of a per-line Python loop, which is what lets mlaunch pass hundreds of
thousands of lines a second while the children keep running. rich is used only for tables and
the status view, and imported only when one is shown.
"""

from __future__ import annotations

import os
import socket
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
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


def clean(data: bytes) -> bytes:
    """Valid UTF-8, with U+FFFD for whatever was not."""
    try:
        data.decode("utf-8")
        return data
    except UnicodeDecodeError:
        return data.decode("utf-8", "replace").encode("utf-8")


def prefix_lines(prefix: bytes, data: bytes) -> bytes:
    """Each line of ``data`` (complete lines, ending in newline) with ``prefix`` before it."""
    return prefix + data[:-1].replace(b"\n", b"\n" + prefix) + b"\n"


class LogFile:
    """An append-only log file that rotates at a size limit (name -> name.1 -> name.2 ...)."""

    def __init__(self, path: str, *, rotate_bytes: int, keep: int) -> None:
        self.path = path
        self.rotate_bytes = rotate_bytes
        self.keep = keep
        self._file: IO[bytes] = open(path, "ab", buffering=256 * 1024)  # noqa: SIM115
        self.size = self._file.tell()

    def write(self, data: bytes) -> None:
        if self.rotate_bytes and self.size + len(data) > self.rotate_bytes and self.size:
            self.rotate()
        self._file.write(data)
        self.size += len(data)

    def rotate(self) -> None:
        self._file.close()
        for i in range(self.keep - 1, 0, -1):
            older = f"{self.path}.{i}"
            if os.path.exists(older):
                os.replace(older, f"{self.path}.{i + 1}")
        if self.keep > 0:
            os.replace(self.path, f"{self.path}.1")
        else:
            os.unlink(self.path)
        self._file = open(self.path, "ab", buffering=256 * 1024)  # noqa: SIM115
        self.size = 0

    def flush(self) -> None:
        self._file.flush()

    def close(self) -> None:
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
    path = os.path.join(base, f"{stamp}-{micro}-{socket.gethostname()}-{os.getpid()}")
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


@dataclass
class Printer:
    """Owns the terminal and the log files of a run."""

    out: Callable[[bytes], object] = field(default=lambda data: os.write(1, data))
    color: bool = False
    log_dir: str | None = None
    rotate_bytes: int = DEFAULT_ROTATE_BYTES
    rotate_keep: int = DEFAULT_ROTATE_KEEP
    quiet: bool = False
    clock: Callable[[], float] = time.time

    def __post_init__(self) -> None:
        self._launch_log: LogFile | None = None
        self._own: dict[str, LogFile] = {}
        self._prefix: dict[str, bytes] = {}
        self._dirty = False
        self.hooks: list[Callable[[str, str, bytes], None]] = []
        if self.log_dir:
            self._launch_log = self._open("launch.log")

    def _open(self, name: str) -> LogFile:
        assert self.log_dir is not None
        return LogFile(
            os.path.join(self.log_dir, name), rotate_bytes=self.rotate_bytes, keep=self.rotate_keep
        )

    # --- launch's own messages ----------------------------------------------------------------

    def message(self, level: str, source: str, text: str) -> None:
        """``[LEVEL] [source]: text`` on screen and in launch.log."""
        line = f"[{level}] [{source}]: {text}\n".encode("utf-8", "replace")
        if not self.quiet or level in ("WARNING", "ERROR"):
            if self.color and LEVEL_COLORS.get(level):
                self.out(LEVEL_COLORS[level] + line[:-1] + RESET + b"\n")
            else:
                self.out(line)
        if self._launch_log is not None:
            self._launch_log.write(b"%.7f " % self.clock() + line)
            self._dirty = True

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
            self.out(prefix_lines(self._prefix[label], data))
        own = self._own.get(label)
        if own is not None:
            own.write(data)
            self._dirty = True
        if self._launch_log is not None and mode in LAUNCH_LOG_MODES:
            self._launch_log.write(
                prefix_lines(b"%.7f [%s] " % (self.clock(), label.encode()), data)
            )
            self._dirty = True
        for hook in self.hooks:
            hook(label, stream, data)

    def flush(self) -> None:
        """Push buffered log lines to disk (called when the supervisor is about to wait)."""
        if not self._dirty:
            return
        if self._launch_log is not None:
            self._launch_log.flush()
        for f in self._own.values():
            f.flush()
        self._dirty = False

    def close(self) -> None:
        self.flush()
        if self._launch_log is not None:
            self._launch_log.close()
        for f in self._own.values():
            f.close()


def stdout_is_color_terminal(environ: Mapping[str, str]) -> bool:
    if environ.get("NO_COLOR"):
        return False
    if environ.get("FORCE_COLOR") or environ.get("RCUTILS_COLORIZED_OUTPUT") == "1":
        return True
    return sys.stdout.isatty() and environ.get("TERM") != "dumb"
