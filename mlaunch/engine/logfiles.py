"""The run's log folder and its files: ``launch.log`` and one rotating file per process.

Log files get every line (the screen may drop some for a stalled reader, never these). A file is
opened on its first write, buffered, and rotated at a size limit: ``name`` is the newest part,
``name.1`` the one before, and so on; ``keep`` says how many rotated parts stay (``ALL``: every
one, so nothing is ever dropped). What is kept is the user's choice (``--log-max-bytes``,
``--log-keep``) and the README says exactly what it is.
"""

from __future__ import annotations

import errno
import os
import time
from collections.abc import Callable, Mapping

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import IO

DEFAULT_ROTATE_BYTES = 64 * 1024 * 1024
DEFAULT_ROTATE_KEEP = 3
ALL = -1  # keep: every rotated part stays
# Per log file: a hundred processes must not pin a hundred large buffers.
LOG_BUFFER = 64 * 1024


def log_file_name(label: str) -> str:
    """The file a process's lines go to in the log folder: ``<label>.log``, always inside it.

    A label is the launch file's ``name``, which may hold ``/`` or ``..``: ``%`` and ``/`` are
    written as ``%25`` and ``%2F`` (so two labels never share a file), and a name that starts
    with a dot keeps it (``..`` gives ``...log``, a file of the folder, not its parent).
    """
    return label.replace("%", "%25").replace("/", "%2F").replace("\0", "%00") + ".log"


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
        self.rotated = 0  # parts made by rotation so far (with keep=ALL, all still on disk)
        self._file: IO[bytes] | None = None
        if not lazy:
            self._open()

    def _open(self) -> None:
        # Never through a link someone put at the name: only a file of the run's own folder.
        flags = os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC
        try:
            fd = os.open(self.path, flags, 0o666)
        except OSError as e:
            if e.errno == errno.ELOOP:
                raise OSError(e.errno, "a symlink stands at its name (never written through)")
            raise
        self._file = open(fd, "ab", buffering=LOG_BUFFER)  # noqa: SIM115
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
        # The oldest kept part is overwritten (dropped) by the one before it; with ALL, none is.
        last = self.rotated + 1 if self.keep == ALL else self.keep
        for i in range(last - 1, 0, -1):
            older = f"{self.path}.{i}"
            if os.path.exists(older):
                os.replace(older, f"{self.path}.{i + 1}")
        if self.keep != 0:
            os.replace(self.path, f"{self.path}.1")
        else:
            os.unlink(self.path)
        self.rotated += 1
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


# What one tail may read, whatever it is asked for: the supervisor's loop reads it between two
# turns (4 MiB: ~5 ms from the page cache).
TAIL_MAX_BYTES = 4 * 1024 * 1024


def tail_lines(
    path: str, count: int, *, block: int = 64 * 1024, max_bytes: int = TAIL_MAX_BYTES
) -> list[bytes]:
    """The last ``count`` lines of a log file and its rotated parts (``path.1`` ...), oldest first.

    Read backwards a block at a time, so a 64 MiB log costs a block or two, not the whole file,
    and never more than ``max_bytes`` in all (fewer lines then: the newest ones that fit).
    Lines keep no newline; a missing file has none.
    """
    found: list[bytes] = []
    part = 0
    budget = max_bytes
    while len(found) < count and budget > 0:
        name = path if part == 0 else f"{path}.{part}"
        try:
            with open(name, "rb") as f:
                lines, used = _file_tail(f, count - len(found), block, budget)
        except FileNotFoundError:
            break
        found[:0] = lines
        budget -= used
        part += 1
    return found


def _file_tail(f: IO[bytes], count: int, block: int, budget: int) -> tuple[list[bytes], int]:
    """The last ``count`` lines of one file read backwards within ``budget`` bytes; (lines,
    bytes read). Linear: blocks are kept in a list and their newlines counted once each."""
    pos = f.seek(0, os.SEEK_END)
    blocks: list[bytes] = []
    newlines = 0
    used = 0
    while pos > 0 and newlines <= count and used < budget:
        start = max(0, pos - min(block, budget - used))
        f.seek(start)
        data = f.read(pos - start)
        blocks.append(data)
        newlines += data.count(b"\n")
        used += len(data)
        pos = start
    buf = b"".join(reversed(blocks))
    if buf.endswith(b"\n"):
        buf = buf[:-1]
    lines = buf.split(b"\n") if buf else []
    if pos > 0:
        lines = lines[1:]  # cut by the block boundary (or the budget): its start is further back
    return (lines[-count:] if count > 0 else []), used


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
    """Create ``<base>/<timestamp>-<host>-<pid>/`` and point ``<base>/latest`` at it.

    A base that another user owns, or may write into without the sticky bit (it or a folder
    above it), is refused (UsageError): they could swap the run's folder for a link to the
    caller's own files, which mlaunch would then write into and chmod.
    """
    from mlaunch.engine.ownership import unsafe_base
    from mlaunch.plan.errors import UsageError

    base = log_base_dir(environ)
    os.makedirs(base, exist_ok=True)
    why = unsafe_base(base)
    if why:
        raise UsageError(
            f"the log folder {base} is not safe for this run's logs: {why}, so they could swap"
            " the run's folder for a link to your files; set ROS_LOG_DIR to a folder of your own"
        )
    stamp = time.strftime("%Y-%m-%d-%H-%M-%S", time.localtime())
    micro = f"{time.time() % 1:.6f}"[2:]
    path = os.path.join(base, f"{stamp}-{micro}-{os.uname().nodename}-{os.getpid()}")
    os.mkdir(path)  # a new name of this run's: something already there is not this run's
    latest = os.path.join(base, "latest")
    if not os.path.exists(latest) or os.path.islink(latest):
        tmp = f"{latest}.{os.getpid()}"
        try:
            os.symlink(os.path.basename(path), tmp)
            os.replace(tmp, latest)
        except OSError:
            pass
    return path
