"""Start a child as ``subprocess.Popen`` does, for a third of its cost, importing no subprocess.

``start(argv, env, stdin=..., stdout=..., stderr=...)`` is ``subprocess.Popen(argv, env=env,
stdin=..., stdout=..., stderr=..., start_new_session=True, close_fds=True).pid``: the same child
(a session and process group of its own, fds 0-2 from the given fds and every other fd closed,
SIGPIPE and SIGXFSZ back to their defaults, the program looked up on the *child environment's*
PATH) and the same errors (FileNotFoundError, PermissionError, ... with Popen's errno, text and
filename). It calls the same C function Popen calls, ``_posixsubprocess.fork_exec`` (vfork,
then close_range in the child), without Popen's Python around it: encoding the environment one
variable at a time (~390 calls a child), the file objects, the lock and the bookkeeping. The pid
is the caller's to reap (``os.wait4``); nothing here keeps a reference to the child.

Why not ``os.posix_spawn``: before Python 3.13 it cannot close the fds a C library left
inheritable (rclpy and Fast DDS leave their sockets and shared-memory locks so), which
``close_fds=True`` does and a launch must (a child holding the launcher's DDS port keeps it
after the launcher is gone); listing /proc/self/fd instead costs more than Popen itself once a
launch holds a few hundred pipes. fork_exec is private, so its parameters are checked against
the ones passed here before it is used (``AVAILABLE``); where they differ (a future Python),
callers use ``subprocess.Popen``.

Imports only ``os``, ``sys``, ``errno`` and ``_posixsubprocess`` (a small C module), so a start
path that spawns before the engine is imported pays for nothing else.
"""

from __future__ import annotations

import errno
import os
import sys

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence

# fork_exec's parameters, in the order Python 3.11 to 3.13's subprocess passes them.
_PARAMETERS = (
    "args, executable_list, close_fds, pass_fds, cwd, env, p2cread, p2cwrite, c2pread,"
    " c2pwrite, errread, errwrite, errpipe_read, errpipe_write, restore_signals, call_setsid,"
    " pgid_to_set, gid, extra_groups, uid, child_umask, preexec_fn, allow_vfork"
)


def _fork_exec() -> Callable[..., int] | None:
    """This interpreter's fork_exec when it takes ``_PARAMETERS``, else None."""
    try:
        import _posixsubprocess
    except ImportError:
        return None
    function: Callable[..., int] | None = getattr(_posixsubprocess, "fork_exec", None)
    if function is None:
        return None
    signature = getattr(function, "__text_signature__", None)
    if signature is None:
        # 3.11 has no text signature (its docstring lists an older set); its subprocess.py
        # passes exactly _PARAMETERS.
        return function if sys.version_info[:2] == (3, 11) else None
    names = signature.strip("()").replace("$module,", "").replace("/", "").split(",")
    wanted = _PARAMETERS.split(",")
    if [n.strip() for n in names if n.strip()] != [n.strip() for n in wanted]:
        return None
    return function


_FORK_EXEC = _fork_exec()
# Whether ``start`` can be used in this interpreter (False: use subprocess.Popen).
AVAILABLE = _FORK_EXEC is not None

_FS_ENCODING = sys.getfilesystemencoding()
_FS_ERRORS = sys.getfilesystemencodeerrors()


class Environment:
    """A child environment encoded once, for many starts (a respawn, or one spec's restarts).

    Raises ValueError for a name with "=" in it, as Popen does.
    """

    __slots__ = ("entries", "mapping", "path")

    def __init__(self, env: Mapping[str, str]) -> None:
        enc, errors = _FS_ENCODING, _FS_ERRORS
        entries = []
        for name, value in env.items():
            if type(name) is str and type(value) is str:
                if "=" in name:
                    raise ValueError("illegal environment variable name")
                entries.append(f"{name}={value}".encode(enc, errors))
            else:  # bytes or a path, as Popen takes them; anything else its TypeError
                raw = os.fsencode(name)
                if b"=" in raw:
                    raise ValueError("illegal environment variable name")
                entries.append(raw + b"=" + os.fsencode(value))
        self.entries = entries
        self.mapping = env  # what the audit event names, as Popen's
        # The PATH the program is looked up on (os.get_exec_path's rule: the default if unset).
        path = env.get("PATH")
        self.path: str = os.defpath if path is None else path


# The environments encoded so far, by content: the children of one launch mostly share theirs.
_ENVIRONMENTS: dict[tuple[tuple[str, str], ...], Environment] = {}
_MAX_ENVIRONMENTS = 64


def environment(env: Mapping[str, str]) -> Environment:
    """``env`` encoded, once for every equal mapping (a tuple of its items is ~10x cheaper to
    make and look up than encoding it again)."""
    key = tuple(env.items())
    found = _ENVIRONMENTS.get(key)
    if found is None:
        found = Environment(env)
        if len(_ENVIRONMENTS) >= _MAX_ENVIRONMENTS:
            _ENVIRONMENTS.clear()
        _ENVIRONMENTS[key] = found
    return found


# (program, PATH) -> the candidates Popen would try, in order; bounded (see _candidates).
_LOOKUPS: dict[tuple[str, str], tuple[bytes, ...]] = {}
_MAX_LOOKUPS = 512


def _candidates(program: str, path: str) -> tuple[bytes, ...]:
    """The files exec is tried on, in order: ``program`` itself when it is a path (has a "/"),
    else ``program`` in each folder of ``path`` (an empty entry is the working directory)."""
    key = (program, path)
    found = _LOOKUPS.get(key)
    if found is not None:
        return found
    if "/" in program:
        found = (os.fsencode(program),)
    else:
        found = tuple(os.fsencode(os.path.join(folder, program)) for folder in path.split(":"))
    if len(_LOOKUPS) >= _MAX_LOOKUPS:
        _LOOKUPS.clear()
    _LOOKUPS[key] = found
    return found


class ChildSetupFailed(OSError):
    """``child_setup`` raised in the child before its exec (Popen raises SubprocessError)."""


def start(
    argv: Sequence[str],
    env: Mapping[str, str] | Environment,
    *,
    stdin: int,
    stdout: int,
    stderr: int,
    cwd: str | None = None,
    child_setup: Callable[[], None] | None = None,
) -> int:
    """Start ``argv`` in a new session with ``env``; its pid. Raises OSError as Popen does.

    ``stdin``, ``stdout``, ``stderr``: the fds that become the child's 0, 1 and 2 (the caller
    keeps and closes its own). ``cwd``: the child's working directory (a failure to enter it is
    an OSError naming it). ``child_setup``: run in the child before exec (Popen's
    ``preexec_fn``; the child is then forked, not vforked, which costs more).
    """
    fork_exec = _FORK_EXEC
    if fork_exec is None:
        raise RuntimeError("spawning.start is not available in this Python; use subprocess")
    if not argv:
        raise ValueError("argv is empty: there is no program to start")
    environment = env if isinstance(env, Environment) else Environment(env)
    args = list(argv)
    given = args[0]  # as Popen names it in its errors and its audit event (str, bytes, a path)
    executables = _candidates(os.fsdecode(given), environment.path)
    sys.audit("subprocess.Popen", given, args, cwd, environment.mapping)
    # Popen's protocol: the child writes "Name:hex errno:detail" to this pipe when it cannot
    # exec; the end it writes to is close-on-exec, so a started child leaves it empty.
    errpipe_read, errpipe_write = os.pipe()
    low = []
    while errpipe_write < 3:  # 0-2 are the child's; keep the error pipe out of their way
        low.append(errpipe_write)
        errpipe_write = os.dup(errpipe_write)
    for fd in low:
        os.close(fd)
    try:
        try:
            pid = fork_exec(
                args, executables, True, (errpipe_write,), cwd, environment.entries,
                stdin, -1, -1, stdout, -1, stderr,
                errpipe_read, errpipe_write,
                True, True, -1, None, None, None, -1, child_setup, True,
            )  # fmt: skip
        finally:
            os.close(errpipe_write)
        report = bytearray()
        while True:
            part = os.read(errpipe_read, 50000)
            report += part
            if not part or len(report) > 50000:
                break
    finally:
        os.close(errpipe_read)
    if report:
        _raise_failure(pid, bytes(report), given, cwd)
    return pid


def with_pipes(
    start_child: Callable[[int, int, int], int],
    outputs: tuple[tuple[int, int], tuple[int, int]] | None = None,
) -> tuple[int, int, tuple[int, int]]:
    """``start_child(stdin, stdout, stderr)`` (a pid) with the ends a launch gives a child:
    stdin a pipe nobody writes to, held open while it lives (a child that reads it waits, where
    /dev/null would hand it EOF at once), stdout and stderr pipes, or the (read, write) pairs of
    ``outputs`` (terminals). Returns (pid, stdin's write end, the two read ends); the child's
    ends are closed here, and every end if it raises."""
    made: list[int] = [fd for pair in outputs or () for fd in pair]
    try:
        if outputs is None:
            outputs = (os.pipe(), os.pipe())  # close-on-exec, as every fd here
            made += (*outputs[0], *outputs[1])
        stdin_read, stdin_write = os.pipe()
        made += (stdin_read, stdin_write)
        pid = start_child(stdin_read, outputs[0][1], outputs[1][1])
    except BaseException:
        for fd in made:
            os.close(fd)
        raise
    for fd in (stdin_read, outputs[0][1], outputs[1][1]):
        os.close(fd)
    return pid, stdin_write, (outputs[0][0], outputs[1][0])


def _raise_failure(pid: int, report: bytes, program: object, cwd: str | None) -> None:
    """Reap the child that could not exec and raise what Popen raises for ``report``."""
    try:
        os.waitpid(pid, 0)
    except ChildProcessError:
        pass
    try:
        name, hex_errno, detail = report.split(b":", 2)
        number = int(hex_errno, 16)
    except ValueError:
        raise ChildSetupFailed(0, f"bad report from the child: {report!r}") from None
    if name != b"OSError":
        # fork_exec's only other report: the preexec function raised.
        raise ChildSetupFailed(number or errno.ECHILD, detail.decode(errors="replace"))
    if detail == b"noexec":  # it failed before exec: entering cwd
        raise OSError(number, os.strerror(number), cwd)
    raise OSError(number, os.strerror(number) if number else detail.decode(), program)
