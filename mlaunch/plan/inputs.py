"""What loading and resolving a launch file read, for the plan cache (mlaunch.app.plan_cache).

A cached plan may only be used when nothing it was made from has changed, so the recording has
to see every input, and refuse (``Recording.refusals``) what it cannot see. While a recording is
active (one window: loading and resolving, on one thread or many):

- an audit hook (``sys.addaudithook``) notes each file opened for reading (its content's digest),
  each directory listed (``os.listdir``, ``os.scandir``, and so ``glob`` and ``os.walk``), and
  refuses what makes a plan depend on the moment: a subprocess, a socket, ``ctypes``, a change
  to a file or folder outside the run's own, ``os.chdir``;
- ``os.stat``, ``os.lstat``, ``os.access`` and ``os.readlink`` are wrapped, since a stat has no
  audit event and "does this package exist" is a stat (``os.path.exists``, ``isfile``, ``isdir``,
  ``pathlib`` and ``shutil.which`` go through them): each path's answer is noted;
- the clock, randomness and the process id as launch-file code reads them (``time.time``,
  ``datetime.now``, the ``random`` functions, ``os.urandom``, ``uuid``, ``os.getpid``) are
  wrapped and refuse the plan when code other than mlaunch's own calls them; mlaunch's own
  volatile values (``$(anon)``) say so through ``volatile``.

``Inputs.changed()`` answers, on a later start, whether any noted answer differs now. The
environment, the arguments, mlaunch's code and Python are the cache key's, not the recording's.
"""

from __future__ import annotations

import os
import stat
import sys
import threading

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from types import CodeType
    from typing import Any

# What the audit events below mean for a plan: each name makes it uncacheable, with these words.
REFUSED_EVENTS = {
    "subprocess.Popen": "runs a program",
    "os.system": "runs a program",
    "os.exec": "runs a program",
    "os.posix_spawn": "runs a program",
    "os.spawn": "runs a program",
    "os.fork": "forks",
    "os.forkpty": "forks",
    "pty.spawn": "runs a program",
    "socket.connect": "uses the network",
    "socket.sendto": "uses the network",
    "socket.sendmsg": "uses the network",
    "socket.getaddrinfo": "uses the network",
    "socket.gethostbyname": "uses the network",
    "socket.gethostbyname_ex": "uses the network",
    "socket.gethostbyaddr": "uses the network",
    "socket.getnameinfo": "uses the network",
    "urllib.Request": "uses the network",
    "http.client.connect": "uses the network",
    "ftplib.connect": "uses the network",
    "smtplib.connect": "uses the network",
    "sqlite3.connect": "opens a database",
    "ctypes.dlopen": "loads a C library through ctypes",
    "ctypes.call_function": "calls C code through ctypes",
    "os.chdir": "changes the working directory",
    "os.kill": "signals a process",
    "os.killpg": "signals a process",
}

# Audit events that change the file system: allowed in the run's own folders only.
CHANGING_EVENTS = frozenset(
    {
        "os.remove",
        "os.rename",
        "os.rmdir",
        "os.mkdir",
        "os.symlink",
        "os.link",
        "os.chmod",
        "os.chown",
        "os.truncate",
        "os.utime",
        "shutil.copyfile",
        "shutil.copymode",
        "shutil.copystat",
        "shutil.copytree",
        "shutil.move",
        "shutil.rmtree",
    }
)

_EVENTS = frozenset({"exec", "open", "os.listdir", "os.scandir", *CHANGING_EVENTS, *REFUSED_EVENTS})

_OWN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep  # mlaunch/
_STDLIB_DIRS = (os.path.dirname(os.__file__) + os.sep,)  # lib/python3.X/ (and lib-dynload)
# Read at most this much of a file for its digest; a bigger input makes the plan uncacheable.
MAX_FILE_BYTES = 64 << 20
# A file changed less than this before its entry is stored is read again at every check.
RACY_NS = 2_000_000_000
# At most this many refusals are kept (the first one is what --debug says).
MAX_REFUSALS = 5

_active: Recording | None = None
_hooked = False
_lock = threading.Lock()
_local = threading.local()  # .busy: the recorder's own file system calls are not noted


def volatile(reason: str) -> None:
    """Say that what is being resolved depends on something no input captures ($(anon): a name
    new in every run): the plan being recorded, if any, is not cached."""
    recording = _active
    if recording is not None:
        recording.refuse(reason)


def digest(data: bytes) -> str:
    """A file's content digest (blake2b: ``_blake2`` imports in 0.2 ms, hashlib's OpenSSL in 2)."""
    try:
        from _blake2 import blake2b
    except ImportError:  # an interpreter without the builtin module
        from hashlib import blake2b
    return blake2b(data, digest_size=20).hexdigest()


# --- what was read, and whether it still reads the same ------------------------------------------


class Inputs:
    """The answers a resolution got: files (path -> digest, None when missing), directory
    listings (path -> digest of the names, None when not a folder), stats (kind, path ->
    signature). Plain data (marshal writes it), checked again by ``changed``.

    ``unchanged`` holds, for a file read, its identity (device, inode, size, modification and
    change times) when the digest was taken: while the file still has it, its content is the
    one digested (the change time is the kernel's, set by every write). As git's index does,
    a file changed less than ``RACY_NS`` before the entry is made gets none: a write in the same
    tick of the file system's clock could leave it alike, so it is read again each time.
    """

    __slots__ = ("files", "listings", "probes", "unchanged")

    def __init__(
        self,
        files: dict[str, str | None] | None = None,
        listings: dict[str, str | None] | None = None,
        probes: dict[tuple[str, str], object] | None = None,
        unchanged: dict[str, tuple[int, ...]] | None = None,
    ) -> None:
        self.files: dict[str, str | None] = {} if files is None else files
        self.listings: dict[str, str | None] = {} if listings is None else listings
        self.probes: dict[tuple[str, str], object] = {} if probes is None else probes
        self.unchanged: dict[str, tuple[int, ...]] = {} if unchanged is None else unchanged

    def as_data(self) -> tuple[Any, ...]:
        import time

        settled = time.time_ns() - RACY_NS
        unchanged = {p: ident for p, ident in self.unchanged.items() if ident[4] < settled}
        probes = [(k, p, v) for (k, p), v in self.probes.items()]
        return (self.files, self.listings, probes, unchanged)

    @classmethod
    def from_data(cls, data: Any) -> Inputs:
        files, listings, probes, unchanged = data
        tables = (files, listings, unchanged)
        if not all(isinstance(table, dict) for table in tables):
            raise ValueError("inputs are not three tables")
        return cls(files, listings, {(k, p): v for k, p, v in probes}, unchanged)

    def changed(self) -> str | None:
        """What now answers differently (one phrase), or None when every input is the same."""
        for path, want in self.files.items():
            known = self.unchanged.get(path)
            if known is not None and known == identity(path):
                continue
            if file_digest(path) != want:
                return f"{path} changed"
        for path, want in self.listings.items():
            if listing_digest(path) != want:
                return f"the folder {path} changed"
        for (kind, place), answer in self.probes.items():
            if probe(kind, place) != answer:
                return f"{place} changed ({kind})"
        return None

    def __len__(self) -> int:
        return len(self.files) + len(self.listings) + len(self.probes)


def identity(path: str) -> tuple[int, ...] | None:
    """(device, inode, size, modification ns, change ns) of a file, None when it has none."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def file_digest(path: str) -> str | None:
    """The digest of a file's content; None when it cannot be read as a file."""
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_FILE_BYTES + 1)
    except OSError:
        return None
    return digest(data)


def listing_digest(path: str) -> str | None:
    """The digest of a folder's sorted names (Python's __pycache__, which imports make, left
    out); None when it cannot be listed."""
    try:
        names = [name for name in os.listdir(path) if name != "__pycache__"]
    except OSError:
        return None
    return digest("\0".join(sorted(names)).encode("utf-8", "surrogateescape"))


def probe(kind: str, path: str) -> object:
    """What a stat-like call answers now: its errno, or the parts of the result a plan may use
    (kind of file, permissions; a regular file's size and modification time; a link's target)."""
    try:
        if kind == "readlink":
            return os.readlink(path)
        if kind.startswith("access"):
            return os.access(path, int(kind[6:]))
        st = os.lstat(path) if kind == "lstat" else os.stat(path)
    except OSError as e:
        return e.errno
    except ValueError:  # an embedded NUL
        return -1
    return _signature(st)


def _signature(answer: object) -> object:
    """The parts of a stat result a plan may depend on; any other answer as it is."""
    if not isinstance(answer, os.stat_result):
        return answer
    mode = answer.st_mode
    if stat.S_ISREG(mode):
        return (stat.S_IFMT(mode), mode & 0o7777, answer.st_size, answer.st_mtime_ns)
    return (stat.S_IFMT(mode), mode & 0o7777)


# --- recording ---------------------------------------------------------------------------------


class Recording:
    """One window of loading and resolving: the inputs noted, and why the plan cannot be cached
    (``refusals``, the first few). ``own`` are the run's own folders (its params files'), which
    may be written and whose files are not inputs."""

    def __init__(self, own: tuple[str, ...] = ()) -> None:
        self.inputs = Inputs()
        self.refusals: list[str] = []
        self.written: set[str] = set()  # files written outside the run's own folders
        self.own = tuple(os.path.abspath(d) + os.sep for d in own if d)
        self.cwd = os.getcwd()

    def refuse(self, reason: str) -> None:
        if len(self.refusals) < MAX_REFUSALS and reason not in self.refusals:
            self.refusals.append(reason)

    def _absolute(self, path: object) -> str | None:
        if not isinstance(path, (str, bytes, os.PathLike)):
            return None  # a descriptor: its file was noted when it was opened
        try:
            text = os.fsdecode(path)
        except (TypeError, UnicodeError):
            return None
        return os.path.normpath(os.path.join(self.cwd, text))

    def _owned(self, path: str) -> bool:
        return (path + os.sep).startswith(self.own) if self.own else False

    # the audit hook's cases

    def opened(self, path: object, mode: object, flags: object) -> None:
        absolute = self._absolute(path)
        if absolute is None or self._owned(absolute) or absolute == os.devnull:
            return
        writes = isinstance(flags, int) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT)
        if writes or (isinstance(mode, str) and any(c in mode for c in "wax+")):
            if not _python_cache(absolute):
                self.written.add(absolute)  # refused unless removed in the window (finish)
            return
        if absolute in self.written:
            return  # what the window wrote itself is no input
        if absolute.endswith(".pyc") and "__pycache__" in absolute:
            absolute = _source_of(absolute)
        if absolute in self.inputs.files or absolute in self.inputs.listings:
            return
        if os.path.isdir(absolute):
            self.listed(absolute)
            return
        before = identity(absolute)
        found = file_digest(absolute)
        if before is not None and before[2] > MAX_FILE_BYTES:
            self.refuse(f"reads {absolute}, larger than {MAX_FILE_BYTES >> 20} MiB")
        self.inputs.files[absolute] = found
        if before is not None and found is not None and identity(absolute) == before:
            self.inputs.unchanged[absolute] = before

    def listed(self, path: object) -> None:
        absolute = self._absolute("." if path is None else path)
        known = absolute is None or absolute in self.inputs.listings
        if absolute is not None and not known and not self._owned(absolute):
            self.inputs.listings[absolute] = listing_digest(absolute)

    def changing(self, event: str, args: tuple[Any, ...]) -> None:
        paths = [a for a in args[:2] if isinstance(a, (str, bytes, os.PathLike))]
        for path in paths:
            absolute = self._absolute(path)
            if absolute is None or self._owned(absolute) or _python_cache(absolute):
                continue
            if event == "os.remove" and absolute in self.written:
                self.written.discard(absolute)  # a scratch file, written and removed
                continue
            self.refuse(f"changes {absolute} ({event})")

    def probed(self, kind: str, path: object, answer: object) -> None:
        absolute = self._absolute(path)
        if absolute is None or self._owned(absolute):
            return
        self.inputs.probes.setdefault((kind, absolute), answer)

    def note_loaded_modules(self, names: set[str]) -> None:
        """The code of modules imported before the window that launch-file code may use and
        the key does not cover (not mlaunch's, not the standard library's: site-packages, a
        user's own): a package upgraded is a change."""
        for name in names:
            path = getattr(sys.modules.get(name), "__file__", None)
            if not isinstance(path, str) or path.startswith(_OWN_DIR) or _stdlib(path):
                continue
            if path.endswith(".py"):
                if path not in self.inputs.files:
                    self.inputs.files[path] = file_digest(path)
            else:
                self.inputs.probes.setdefault(("stat", path), probe("stat", path))

    def finish_writes(self) -> None:
        """Refuse the plan for each file written outside the run's folders and left there."""
        for path in sorted(self.written):
            self.refuse(f"writes {path}")

    def finish_modules(self, before: set[str]) -> None:
        """Modules imported in the window whose code no open() showed (C extensions): their
        files' stat, so a rebuilt extension is a change."""
        for name in set(sys.modules) - before:
            path = getattr(sys.modules.get(name), "__file__", None)
            if isinstance(path, str) and not path.endswith((".py", ".pyc")):
                self.inputs.probes.setdefault(("stat", path), probe("stat", path))


def _python_cache(path: str) -> bool:
    """Whether ``path`` is in Python's own cache of compiled modules (written by imports; not
    what a plan is made of)."""
    return path.endswith(os.sep + "__pycache__") or os.sep + "__pycache__" + os.sep in path


def _source_of(pyc: str) -> str:
    """The .py a __pycache__ .pyc was compiled from (an input is the source, which Python
    compares with the .pyc's header; the .pyc alone would miss an edit no import saw yet)."""
    from importlib.util import source_from_cache

    try:
        source = source_from_cache(pyc)
    except ValueError:
        return pyc
    return source if os.path.exists(source) else pyc


def _hook(event: str, args: tuple[Any, ...]) -> None:
    # Called for every audit event of the process from the first recording on (a frame walk
    # raises one per attribute read): the first test must be the cheapest.
    if event not in _EVENTS:
        return
    recording = _active
    if recording is None or getattr(_local, "busy", False):
        return
    if event == "exec":
        if args and hasattr(args[0], "co_names"):
            _scan_code(recording, args[0])
        return
    if event == "open":
        what = "opened"
    elif event in ("os.listdir", "os.scandir"):
        what = "listed"
    elif event in CHANGING_EVENTS:
        what = "changing"
    else:
        reason = REFUSED_EVENTS.get(event)
        if reason is not None:
            recording.refuse(f"{reason} ({event}{_caller()})")
        return
    _local.busy = True
    try:
        if what == "opened":
            recording.opened(*args[:3])
        elif what == "listed":
            recording.listed(args[0] if args else None)
        else:
            recording.changing(event, args)
    except Exception as e:  # the recorder must never break a resolution
        recording.refuse(f"the recorder failed on {event}: {e}")
    finally:
        _local.busy = False


# Attribute names through which code reads the calendar clock with no Python call to wrap
# (datetime's C methods): code run in the window that names them makes the plan uncacheable.
CLOCK_NAMES = frozenset({"now", "today", "utcnow"})


def _scan_code(recording: Recording, code: CodeType) -> None:
    """Refuse the plan when launch-file or package code executed in the window names a clock
    method (``datetime.now()``): the C call itself has no hook, its name in the code does."""
    name = code.co_filename
    if name.startswith((_OWN_DIR, "<frozen")) or _stdlib(name):
        return
    stack = [code]
    while stack:
        current = stack.pop()
        found = CLOCK_NAMES.intersection(current.co_names)
        if found:
            what = sorted(found)[0]
            recording.refuse(f"reads the time ({what}() at {name}:{current.co_firstlineno})")
            return
        stack.extend(c for c in current.co_consts if hasattr(c, "co_names"))


def _stdlib(path: str) -> bool:
    """Whether ``path`` is the standard library's (not a site-packages below it)."""
    return path.startswith(_STDLIB_DIRS) and "-packages" + os.sep not in path


def _caller(depth: int = 2) -> str:
    """`` at FILE:LINE`` of the first frame outside mlaunch and the standard library."""
    frame = sys._getframe(depth)
    while frame is not None:
        name = frame.f_code.co_filename
        if not name.startswith(_OWN_DIR) and not _stdlib(name) and not name.startswith("<frozen"):
            return f" at {name}:{frame.f_lineno}"
        frame = frame.f_back  # type: ignore[assignment]
    return ""


def _from_outside(stdlib_too: bool) -> bool:
    """Whether the caller of a wrapped function is launch-file (or package) code: not mlaunch's,
    and, unless ``stdlib_too``, not the standard library's (logging stamps its records)."""
    frame = sys._getframe(2)
    name = frame.f_code.co_filename
    if name.startswith(_OWN_DIR):
        return False
    return stdlib_too or not _stdlib(name)


# --- the wrappers of calls no audit event covers ----------------------------------------------


def _probing(kind: str, original: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(path: Any, *args: Any, **kwargs: Any) -> Any:
        recording = _active
        if recording is None or getattr(_local, "busy", False) or _dir_fd(kwargs):
            return original(path, *args, **kwargs)
        name = kind
        if kind == "access":
            name = f"access{args[0] if args else kwargs.get('mode', 0)}"
        elif kind == "stat" and kwargs.get("follow_symlinks") is False:
            name = "lstat"
        try:
            result = original(path, *args, **kwargs)
        except OSError as e:
            recording.probed(name, path, e.errno)
            raise
        recording.probed(name, path, _signature(result))
        return result

    wrapper.__wrapped__ = original  # type: ignore[attr-defined]
    return wrapper


def _dir_fd(kwargs: dict[str, Any]) -> bool:
    return kwargs.get("dir_fd") is not None


def _volatile_call(what: str, original: Callable[..., Any], stdlib_too: bool) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        recording = _active
        if recording is not None and _from_outside(stdlib_too):
            recording.refuse(f"reads {what}{_caller()}")
        return original(*args, **kwargs)

    wrapper.__wrapped__ = original  # type: ignore[attr-defined]
    return wrapper


def _patches() -> list[tuple[object, str, Any]]:
    """(owner, attribute, wrapper) for each call wrapped while recording."""
    import random
    import time

    patches: list[tuple[object, str, Any]] = []
    for kind, name in (("stat", "stat"), ("lstat", "lstat"), ("access", "access")):
        patches.append((os, name, _probing(kind, getattr(os, name))))
    patches.append((os, "readlink", _probing("readlink", os.readlink)))
    for name in ("time", "time_ns", "localtime", "gmtime", "ctime", "asctime", "strftime"):
        patches.append((time, name, _volatile_call("the time", getattr(time, name), False)))
    patches.append((os, "urandom", _volatile_call("random bytes", os.urandom, True)))
    patches.append((os, "getpid", _volatile_call("the process id", os.getpid, False)))
    for name in random.__all__:
        value = getattr(random, name, None)
        if callable(value) and not isinstance(value, type) and name != "seed":
            patches.append((random, name, _volatile_call("random numbers", value, True)))
    if "uuid" in sys.modules:  # imported later, the wrapped os.urandom covers uuid4
        uuid = sys.modules["uuid"]
        for name in ("uuid1", "uuid4"):
            patches.append((uuid, name, _volatile_call("a new UUID", getattr(uuid, name), True)))
    return patches


class paused:
    """``with paused():`` what this thread does is not noted (mlaunch's own work in the window,
    such as making the run's log folder)."""

    def __enter__(self) -> None:
        self._was = getattr(_local, "busy", False)
        _local.busy = True

    def __exit__(self, *exc_info: object) -> None:
        _local.busy = self._was


class record:
    """``with record(own_dirs) as recording:`` notes what the code inside reads (one at a time:
    a nested or concurrent recording refuses both)."""

    def __init__(self, own: tuple[str, ...] = ()) -> None:
        self.recording = Recording(own)
        self._undo: list[tuple[object, str, Any]] = []
        self._modules: set[str] = set()
        self._environ: dict[str, str] = {}
        self._path: list[str] = []

    def __enter__(self) -> Recording:
        global _active, _hooked
        with _lock:
            if _active is not None:
                _active.refuse("two resolutions were recorded at once")
                self.recording.refuse("two resolutions were recorded at once")
                return self.recording
            if not _hooked:
                sys.addaudithook(_hook)  # for the process's life: it returns at once when idle
                _hooked = True
            for owner, name, wrapper in _patches():
                self._undo.append((owner, name, getattr(owner, name)))
                setattr(owner, name, wrapper)
            self._modules = set(sys.modules)
            self._environ = dict(os.environ)
            self._path = list(sys.path)
            _active = self.recording
        return self.recording

    def __exit__(self, *exc_info: object) -> None:
        global _active
        with _lock:
            if _active is not self.recording:
                return
            _active = None
            for owner, name, original in reversed(self._undo):
                setattr(owner, name, original)
        recording = self.recording
        if dict(os.environ) != self._environ:
            recording.refuse("the launch file changed mlaunch's own environment (os.environ)")
        if sys.path != self._path:
            recording.refuse("the launch file changed sys.path")
        _local.busy = True
        try:
            recording.finish_modules(self._modules)
            recording.note_loaded_modules(self._modules)
            recording.finish_writes()
        finally:
            _local.busy = False
