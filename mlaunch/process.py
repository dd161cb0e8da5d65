"""One supervised child: spawn it in its own session, stream its output, signal its group."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from mlaunch.plan import ProcessSpec

READ_SIZE = 256 * 1024
# A line longer than this without a newline is passed on in pieces, so an endless line can
# neither grow memory nor hide output until the process exits.
MAX_PARTIAL = 64 * 1024


def describe_status(returncode: int) -> str:
    """'exited with status 1', 'killed by SIGSEGV'."""
    if returncode < 0:
        return f"killed by {signal_name(-returncode)}"
    return f"exited with status {returncode}"


def signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


@dataclass
class Stream:
    """One pipe from a child: its fd and the partial line not yet complete."""

    name: str
    fd: int
    file: object = None
    partial: bytes = b""


@dataclass
class Process:
    """A running (or finished) instance of a ProcessSpec; respawns get a new Process."""

    spec: ProcessSpec
    index: int
    restarts: int = 0
    pid: int = 0
    returncode: int | None = None
    started_at: float = 0.0
    ended_at: float = 0.0
    streams: dict[int, Stream] = field(default_factory=dict)
    popen: subprocess.Popen[bytes] | None = None
    stopping: bool = False
    signals_sent: list[int] = field(default_factory=list)
    group_alive: bool = True
    core_dumped: bool = False

    @property
    def label(self) -> str:
        return self.spec.label

    @property
    def action(self) -> object:
        return self.spec.action

    @property
    def argv(self) -> tuple[str, ...]:
        return self.spec.argv

    @property
    def running(self) -> bool:
        return self.pid != 0 and self.returncode is None

    def spawn(self, clock: Callable[[], float] = time.monotonic) -> None:
        """Start the child in a new session (its own process group), output on pipes.

        Raises OSError when the program cannot be started.
        """
        spec = self.spec
        args: list[str] | str = list(spec.argv)
        if spec.shell:
            # ROS 2 joins the command with spaces and hands it to /bin/sh, unquoted.
            args = " ".join(spec.argv)
        self.popen = subprocess.Popen(
            args,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=spec.env,
            cwd=spec.cwd,
            shell=spec.shell,
            start_new_session=True,
            close_fds=True,
        )
        self.pid = self.popen.pid
        self.started_at = clock()
        for name, pipe in (("stdout", self.popen.stdout), ("stderr", self.popen.stderr)):
            assert pipe is not None
            fd = pipe.fileno()
            os.set_blocking(fd, False)
            self.streams[fd] = Stream(name, fd, pipe)

    def read(self, fd: int) -> tuple[bytes, bool]:
        """Complete lines available on ``fd`` (may be b"") and whether the pipe reached EOF."""
        stream = self.streams[fd]
        try:
            data = os.read(fd, READ_SIZE)
        except BlockingIOError:
            return b"", False
        except OSError:
            data = b""
        if not data:
            rest = stream.partial
            stream.partial = b""
            return (rest + b"\n" if rest else b""), True
        buf = stream.partial + data if stream.partial else data
        cut = buf.rfind(b"\n")
        if cut < 0:
            if len(buf) > MAX_PARTIAL:
                stream.partial = b""
                return buf + b"\n", False
            stream.partial = buf
            return b"", False
        stream.partial = buf[cut + 1 :]
        if len(stream.partial) > MAX_PARTIAL:
            complete = buf + b"\n"
            stream.partial = b""
            return complete, False
        return buf[: cut + 1], False

    def close_stream(self, fd: int) -> None:
        stream = self.streams.pop(fd, None)
        if stream is not None and stream.file is not None:
            stream.file.close()  # type: ignore[attr-defined]

    def reaped(self, status: int, clock: Callable[[], float] = time.monotonic) -> None:
        """Record the wait status of the leader (raw, from os.waitpid)."""
        code = os.waitstatus_to_exitcode(status)
        self.returncode = code
        self.core_dumped = os.WIFSIGNALED(status) and os.WCOREDUMP(status)
        self.ended_at = clock()
        if self.popen is not None:
            # We reaped it ourselves; tell Popen so it never waits for this pid again.
            self.popen.returncode = code

    def signal_group(self, sig: int) -> bool:
        """Send ``sig`` to the child's process group; False when nothing is left in it."""
        if not self.pid:
            return False
        try:
            os.killpg(self.pid, sig)
        except ProcessLookupError:
            self.group_alive = False
            return False
        except PermissionError:
            return False
        self.signals_sent.append(sig)
        return True

    def check_group(self) -> bool:
        """Whether any process is left in the child's group (the leader may be gone)."""
        if not self.pid or not self.group_alive:
            return False
        try:
            os.killpg(self.pid, 0)
        except ProcessLookupError:
            self.group_alive = False
        except PermissionError:
            pass
        return self.group_alive
