"""One supervised child: spawn it in its own session, stream its output, signal its group."""

from __future__ import annotations

import errno
import os
import signal
import time
from collections.abc import Callable, Mapping, Sequence

from mlaunch.engine import spawning

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    import subprocess

    from mlaunch.plan.steps import ProcessSpec

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


# Signals whose default action writes a core dump (signal(7)).
CORE_SIGNALS = frozenset(
    {signal.SIGQUIT, signal.SIGILL, signal.SIGTRAP, signal.SIGABRT, signal.SIGBUS,
     signal.SIGFPE, signal.SIGSEGV, signal.SIGXCPU, signal.SIGXFSZ, signal.SIGSYS}
)  # fmt: skip


def read_core_pattern() -> tuple[str, bool]:
    """``/proc/sys/kernel/core_pattern`` and ``core_uses_pid`` (empty/False where unreadable)."""
    try:
        with open("/proc/sys/kernel/core_pattern") as f:
            pattern = f.read().strip()
    except OSError:
        return "", False
    try:
        with open("/proc/sys/kernel/core_uses_pid") as f:
            uses_pid = f.read().strip() == "1"
    except OSError:
        uses_pid = False
    return pattern, uses_pid


def core_limit() -> int:
    """The soft RLIMIT_CORE children inherit from mlaunch (-1 for unlimited)."""
    import resource

    soft, _ = resource.getrlimit(resource.RLIMIT_CORE)
    return -1 if soft == resource.RLIM_INFINITY else soft


def core_dump_hint(
    *,
    pid: int,
    signal_number: int,
    dumped: bool,
    executable: str,
    cwd: str,
    pattern: str,
    uses_pid: bool = False,
    limit: int = -1,
) -> str | None:
    """Where the core dump of a crashed process went, or why there is none (None: no core signal).

    rosmon's habit: read core_pattern. A ``|systemd-coredump`` pipe means ``coredumpctl gdb PID``;
    another pipe names its handler; a path pattern gives the expected file (relative paths are
    relative to the process's working directory); RLIMIT_CORE 0 means core dumps are off.
    """
    if signal_number not in CORE_SIGNALS:
        return None
    if not dumped:
        if limit == 0:
            return "core dumps are off (ulimit -c is 0; 'ulimit -c unlimited' turns them on)"
        return "no core dump was written"
    if pattern.startswith("|"):
        handler = pattern[1:].split()[0] if pattern[1:].split() else "?"
        if "systemd-coredump" in handler:
            return f"core dump kept by systemd-coredump: coredumpctl gdb {pid}"
        return f"core dump handed to {handler}"
    path = expand_core_pattern(pattern or "core", pid=pid, executable=executable)
    if uses_pid and "%p" not in pattern:
        path += f".{pid}"
    if not os.path.isabs(path):
        path = os.path.join(cwd, path)
    return f"core dump expected at {path} (gdb {executable} {path})"


def expand_core_pattern(pattern: str, *, pid: int, executable: str) -> str:
    """The ``%`` specifiers of core(5) we can know; the others (time, ...) become ``*``."""
    known = {
        "p": str(pid),
        "P": str(pid),
        "i": str(pid),
        "I": str(pid),
        "e": os.path.basename(executable)[:15],
        "u": str(os.getuid()),
        "g": str(os.getgid()),
        "h": os.uname().nodename,
        "%": "%",
    }
    out = []
    i = 0
    while i < len(pattern):
        ch = pattern[i]
        if ch == "%" and i + 1 < len(pattern):
            out.append(known.get(pattern[i + 1], "*"))
            i += 2
            continue
        out.append(ch)
        i += 1
    return "".join(out)


def utf8_safe_cut(buf: bytes) -> int:
    """How much of ``buf`` to pass on so that it does not end inside a UTF-8 character.

    Used when an endless line is cut into pieces: the next piece starts with the rest.
    """
    n = len(buf)
    for back in range(1, min(4, n) + 1):
        byte = buf[n - back]
        if byte < 0x80:
            return n  # ASCII: nothing is cut
        if byte >= 0xC0:  # the lead byte of the last character
            need = 2 if byte < 0xE0 else 3 if byte < 0xF0 else 4
            return n if back >= need else n - back
    return n


def _ptys() -> tuple[tuple[int, int], tuple[int, int]]:
    """Two (master, slave) pseudo-terminals for a child's stdout and stderr (emulate_tty).

    As launch does, so programs that colour or line-buffer only on a terminal behave as under
    ros2 launch. The slaves do not turn "\n" into "\r\n", so lines read back unchanged.
    """
    import termios

    pairs = []
    for _ in range(2):
        master, slave = os.openpty()
        attrs = termios.tcgetattr(slave)
        attrs[1] &= ~termios.ONLCR
        termios.tcsetattr(slave, termios.TCSANOW, attrs)
        pairs.append((master, slave))
    return pairs[0], pairs[1]


def unstartable(argv: Sequence[str], env: Mapping[str, str], cwd: str | None) -> str | None:
    """Why no exec can take these values (a NUL byte ends a C string; "=" ends a variable's
    name), naming the first bad one; None when none is."""
    for i, arg in enumerate(argv):
        if "\0" in arg:
            what = "the program's name" if i == 0 else f"argument {i}"
            return f"{what} {arg!r} holds a NUL byte, which no program argument can"
    for name, value in env.items():
        if "=" in name or "\0" in name:
            return f"environment variable name {name!r} holds '=' or a NUL byte, which no name can"
        if "\0" in value:
            return f"environment variable {name} is {value!r}: a NUL byte, which no value can hold"
    if cwd is not None and "\0" in cwd:
        return f"the working directory {cwd!r} holds a NUL byte, which no path can"
    return None


class Stream:
    """One pipe from a child: its fd and the partial line not yet complete."""

    __slots__ = ("fd", "file", "name", "partial")

    def __init__(self, name: str, fd: int, file: object = None) -> None:
        self.name = name
        self.fd = fd
        self.file = file
        self.partial = b""


class Process:
    """A running (or finished) instance of a ProcessSpec; respawns get a new Process.

    A plain class, not a dataclass: dataclasses costs milliseconds to import and to build a
    class, paid before the first child starts. Compared by identity (one object per instance).
    """

    __slots__ = (
        "core_dumped",
        "cpu_time",
        "ended_at",
        "group_alive",
        "index",
        "peak_rss",
        "pid",
        "popen",
        "restarts",
        "returncode",
        "signals_sent",
        "spec",
        "started_at",
        "stdin_fd",
        "stopping",
        "streams",
        "user_stop",
    )

    # Start children with engine.spawning (False: subprocess.Popen, as on a Python whose
    # fork_exec spawning does not know; the engine's tests run both).
    direct = spawning.AVAILABLE

    def __init__(self, spec: ProcessSpec, index: int, restarts: int = 0) -> None:
        self.spec = spec
        self.index = index
        self.restarts = restarts
        self.pid = 0
        self.returncode: int | None = None
        self.started_at = 0.0
        self.ended_at = 0.0
        self.streams: dict[int, Stream] = {}
        self.popen: subprocess.Popen[bytes] | None = None
        # The write end of the child's stdin pipe, held open while the child lives; -1: none.
        self.stdin_fd = -1
        self.stopping = False
        # "stop" or "restart" when the user asked for its stop (mlaunch.parts.control), else "".
        self.user_stop = ""
        self.signals_sent: list[int] = []
        self.group_alive = True
        self.core_dumped = False
        self.peak_rss = 0  # bytes, from wait4's rusage (the peak, not a sample)
        self.cpu_time = 0.0  # user + system seconds

    def __repr__(self) -> str:
        return (
            f"Process(label={self.spec.label!r}, pid={self.pid}, returncode={self.returncode},"
            f" restarts={self.restarts})"
        )

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

    def spawn(
        self,
        clock: Callable[[], float] = time.monotonic,
        extra_env: Mapping[str, str] | None = None,
    ) -> None:
        """Start the child in a new session (its own process group), output on pipes.

        ``extra_env`` is added to the spec's environment (the run's marker). Raises OSError when
        the program cannot be started.
        """
        spec = self.spec
        env = {**spec.env, **extra_env} if extra_env else spec.env
        # ROS 2 joins the command with spaces and hands it to /bin/sh, unquoted (Popen's
        # shell=True makes this same argv).
        argv = ("/bin/sh", "-c", " ".join(spec.argv)) if spec.shell else spec.argv
        from mlaunch.engine import fdlimit

        # The user's own open-file limit, when the run raised its own (only then).
        setup = fdlimit.LIMIT.child_setup() if fdlimit.LIMIT is not None else None

        def start_child(stdin: int, out: int, err: int) -> int:
            try:
                if self.direct:
                    return spawning.start(
                        argv,
                        spawning.environment(env),
                        stdin=stdin,
                        stdout=out,
                        stderr=err,
                        cwd=spec.cwd,
                        child_setup=setup,
                    )
                return self._popen(argv, env, stdin, out, err, setup)
            except ValueError as e:  # a value no exec can take: this child fails to start
                raise OSError(errno.EINVAL, unstartable(argv, env, spec.cwd) or str(e)) from e

        # stdout and stderr on pipes, or (master, slave) terminals for emulate_tty; stdin's
        # write end is held (``stdin_fd``) and only ever closed, so it is a bare fd.
        outputs = _ptys() if spec.emulate_tty else None
        self.pid, self.stdin_fd, reads = spawning.with_pipes(start_child, outputs)
        self.started_at = clock()
        for name, read in zip(("stdout", "stderr"), reads, strict=True):
            # the read end sees EOF (a pty EIO) once the child is gone
            os.set_blocking(read, False)
            self.streams[read] = Stream(name, read)

    def _popen(
        self,
        argv: tuple[str, ...],
        env: Mapping[str, str],
        stdin: int,
        stdout: int,
        stderr: int,
        setup: Callable[[], None] | None,
    ) -> int:
        """Start the child with subprocess.Popen (a Python whose fork_exec engine.spawning
        does not know): the same child, at three times the cost; its pid."""
        import subprocess

        self.popen = subprocess.Popen(
            argv,
            stdin=stdin,
            stdout=stdout,
            stderr=stderr,
            env=env,
            cwd=self.spec.cwd,
            start_new_session=True,
            close_fds=True,
            preexec_fn=setup,
        )
        return self.popen.pid

    def adopt(self, pid: int, fds: tuple[int, int, int], started_at: float) -> None:
        """Take over a child the quick start started as this spec (mlaunch.app.quick): its
        pid, its stdin pipe's write end and stdout and stderr pipes' read ends (``fds``)."""
        self.pid = pid
        self.stdin_fd = fds[0]
        self.started_at = started_at
        for name, fd in (("stdout", fds[1]), ("stderr", fds[2])):
            os.set_blocking(fd, False)
            self.streams[fd] = Stream(name, fd)

    def watch_pipes(self) -> None:
        """Take a Popen's stdout and stderr as non-blocking streams (a subclass's spawn)."""
        assert self.popen is not None
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
        if len(buf) - cut - 1 > MAX_PARTIAL:
            # An endless line: pass it on in pieces (bounded memory, output not held back),
            # never splitting a UTF-8 character between two pieces.
            end = utf8_safe_cut(buf)
            stream.partial = buf[end:]
            return buf[:end] + b"\n", False
        if cut < 0:
            stream.partial = buf
            return b"", False
        stream.partial = buf[cut + 1 :]
        return buf[: cut + 1], False

    def close_stream(self, fd: int) -> None:
        stream = self.streams.pop(fd, None)
        if stream is not None and stream.file is not None:
            stream.file.close()  # type: ignore[attr-defined]
        elif stream is not None:
            os.close(fd)  # a bare pipe or pty master

    def reaped(
        self,
        status: int,
        clock: Callable[[], float] = time.monotonic,
        rusage: object | None = None,
    ) -> None:
        """Record the wait status of the leader (raw, from os.wait4) and its resource usage."""
        code = os.waitstatus_to_exitcode(status)
        self.returncode = code
        self.core_dumped = os.WIFSIGNALED(status) and os.WCOREDUMP(status)
        self.ended_at = clock()
        if rusage is not None:
            self.peak_rss = int(rusage.ru_maxrss) * 1024  # type: ignore[attr-defined]  # KiB
            self.cpu_time = rusage.ru_utime + rusage.ru_stime  # type: ignore[attr-defined]
        if self.stdin_fd >= 0:  # what is left of its group reads EOF from now on
            os.close(self.stdin_fd)
            self.stdin_fd = -1
        if self.popen is not None:
            # We reaped it ourselves; tell Popen so it never waits for this pid again.
            self.popen.returncode = code
            if self.popen.stdin is not None:
                try:  # what is left of its group reads EOF from now on
                    self.popen.stdin.close()
                except OSError:
                    pass  # something written to it (a subclass's) found no reader

    def signal_group(self, sig: int, *, wake: bool = False) -> bool:
        """Send ``sig`` to the child's process group; False when nothing is left in it.

        ``wake`` adds SIGCONT, so that a stopped (SIGSTOP, Ctrl-Z) member handles ``sig`` now
        instead of whenever someone continues it.
        """
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
        if wake and sig not in (signal.SIGKILL, signal.SIGCONT):
            try:
                os.killpg(self.pid, signal.SIGCONT)
            except OSError:
                pass
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


def wait_child(pids: Mapping[int, object] | None) -> tuple[int, int, object]:
    """An exited child not yet reaped (any child, or one of ``pids``); pid 0 when none."""
    if pids is None:
        try:
            return os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return 0, 0, None
    for pid in list(pids):
        try:
            found = os.wait4(pid, os.WNOHANG)
        except ChildProcessError:
            continue  # not ours to wait for (any more)
        if found[0]:
            return found
    return 0, 0, None
