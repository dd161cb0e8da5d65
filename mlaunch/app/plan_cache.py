"""The plan cache: a repeated start of the same launch takes its Plan from disk, not from
loading and resolving again (ros2/launch#721), and never a plan any input of which changed.

An entry is found by a key of everything known before loading: the command line's options and
arguments, the whole environment (every process of the plan inherits it), the working folder,
the user, the computer, Python and mlaunch's own code. It holds what the resolution read
(mlaunch.plan.inputs: each file's content digest, each folder listing, each stat), checked again
before the plan is used, and the plan itself, pickled with the run's resolve options and label
counter. A resolution the recording could not see through (a subprocess, the network, the
clock, randomness, a write outside the run's folder, a plan that holds launch-file code) is not
stored: ``--debug`` and ``--print`` say why. docs/plan-cache.md has the rules.

The folder (``$XDG_CACHE_HOME/mlaunch/plans``, else ``~/.cache/mlaunch/plans``) is the user's
own: 0700, entries 0600, written atomically (a temporary file renamed), at most
``MAX_TOTAL_BYTES`` (the least recently used go first). An entry that is not the user's, not
private, corrupt or made for another key is ignored with one line, and never unpickled.
"""

from __future__ import annotations

import os
import pickle
import time
from types import FunctionType

from mlaunch.app.options import cache_wanted
from mlaunch.app.quick import (
    REORDERED,
    cache_folder,
    environment_key,
    host_key,
    read_private,
    write_files,
    write_private,
)
from mlaunch.app.quick import SUFFIX as QUICK
from mlaunch.plan import inputs as plan_inputs

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping
    from typing import Any

    from mlaunch.app.options import Options
    from mlaunch.plan.steps import Plan
    from mlaunch.resolve.resolver import LabelCounter, ResolveOptions

FORMAT = b"mlaunch plan cache 2\n"
MAX_ENTRY_BYTES = 32 << 20
MAX_TOTAL_BYTES = 256 << 20
_DIGEST_CHARS = 40  # plan_inputs.digest: 20 bytes in hex
_MLAUNCH_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Cached:
    """A plan taken from the cache: the launch file, the plan, the options and label counter
    it was resolved with (their folders the new run's)."""

    __slots__ = ("labels", "options", "path", "plan")

    def __init__(self, path: str, plan: Plan, options: ResolveOptions, labels: LabelCounter):
        self.path = path
        self.plan = plan
        self.options = options
        self.labels = labels


class Entry:
    """A sound entry whose inputs are unchanged: the pickled plan and the folders it names."""

    __slots__ = ("inputs", "payload", "places")

    def __init__(self, payload: bytes, places: tuple[str, ...], inputs: int) -> None:
        self.payload = payload
        self.places = places  # the run's temp folder, log folder, run id: rebased when taken
        self.inputs = inputs


def enabled(opts: Options, environ: Mapping[str, str]) -> bool:
    """Whether this run may use the cache (a native ROS 1 run is refused while loading)."""
    return cache_wanted(opts, environ)


# Options that do not change the plan (how it is shown, how the run looks, logs, metrics): every
# other option is in the key, an option added later too.
NOT_IN_KEY = frozenset(
    {
        "format",
        "debug",
        "cache",
        "show_args",
        "check",
        "status",
        "quiet",
        "color",
        "log_max_bytes",
        "log_keep",
        "dashboard_port",
        "metrics",
    }
)


def run_key(opts: Options, environ: Mapping[str, str]) -> str:
    """The digest of everything a plan depends on that is known before the launch file is read."""
    parts = (
        FORMAT,
        _code_fingerprint(),
        host_key(),
        environment_key(environ),
        [(name, value) for name, value in vars(opts).items() if name not in NOT_IN_KEY],
    )
    return plan_inputs.digest(repr(parts).encode("utf-8", "surrogateescape"))


def places(temp_dir: str, log_dir: str, run_id: str, environ: Mapping[str, str]) -> tuple[str, ...]:
    """What differs between two runs of the same plan, rebased wherever the plan names it: the
    run's temp folder (first: its params files), log folder, run id, REORDERED variables."""
    return (temp_dir, log_dir, run_id, *(environ.get(name, "") for name in REORDERED))


def _code_fingerprint() -> list[tuple[str, int, int]]:
    """mlaunch's own files as (path, size, modification time): an edit or an upgrade of
    mlaunch is a new key (what the modules it imports while resolving are is recorded too)."""
    found = []
    stack = [_MLAUNCH_DIR]
    while stack:
        folder = stack.pop()
        with os.scandir(folder) as entries:
            for entry in entries:
                if entry.name == "__pycache__":
                    continue
                if entry.is_dir(follow_symlinks=False):
                    stack.append(entry.path)
                elif entry.name.endswith(".py"):
                    st = entry.stat()
                    found.append((entry.path, st.st_size, st.st_mtime_ns))
    found.sort()
    return found


class PlanCache:
    """The entry of one run's key in the user's cache folder. ``say`` writes one line (a
    problem with the cache, never fatal); ``debug`` lines are said only with --debug."""

    def __init__(
        self,
        folder: str,
        key: str,
        say: Callable[[str], None],
        debug: bool,
        limit: int = MAX_TOTAL_BYTES,
    ) -> None:
        self.folder = folder
        self.limit = limit  # the folder's size at most, in bytes
        self.key = key
        self.file = os.path.join(folder, key + ".plan")
        self._say = say
        self._debug = debug
        self.why_not = ""  # why the last resolution was not stored ("" when it was)
        # What the plan found or stored was resolved from (Inputs.as_data), for the quick start.
        self.inputs_data: Any = None
        # --debug says how long finding the plan took, in wall-clock and CPU time
        self._started = (time.perf_counter(), time.process_time())

    @classmethod
    def for_run(
        cls, opts: Options, environ: Mapping[str, str], say: Callable[[str], None]
    ) -> PlanCache | None:
        if not enabled(opts, environ):
            return None
        return cls(cache_folder(environ), run_key(opts, environ), say, opts.debug)

    def _elapsed(self) -> tuple[int, int]:
        """Milliseconds since this run's cache was looked for: wall-clock, CPU."""
        wall, cpu = self._started
        return (
            round((time.perf_counter() - wall) * 1000),
            round((time.process_time() - cpu) * 1000),
        )

    def debug(self, text: str) -> None:
        if self._debug:
            self._say(f"mlaunch: plan cache: {text}")

    # --- reading ------------------------------------------------------------------------------

    def lookup(self) -> Entry | None:
        """The entry of this key when it is sound and every input it records reads the same."""
        data = self._read()
        if data is None:
            return None
        try:
            header, payload = _split(data)
        except ValueError as e:
            self._ignore(f"corrupt ({e})")
            return None
        if header.get("key") != self.key:
            self._ignore("made for another key")
            return None
        try:
            recorded = plan_inputs.Inputs.from_data(header["inputs"])
            changed = recorded.changed()
            places = tuple(str(place) for place in header["places"])
        except (KeyError, TypeError, ValueError) as e:
            self._ignore(f"corrupt ({type(e).__name__}: {e})")
            return None
        if changed is not None:
            self.debug(f"resolving again: {changed}")
            return None
        self.inputs_data = header["inputs"]
        return Entry(payload, places, len(recorded))

    def take(self, entry: Entry, places: tuple[str, ...]) -> Cached | None:
        """The entry's plan, rebased onto this run's ``places`` (its temp folder, where its
        params files are written again, its log folder and run id); None (said) when it cannot
        be read back."""
        if len(places) != len(entry.places):
            self._ignore("made for other places")
            return None
        temp_dir = places[0]
        try:
            path, plan, options, labels, made = _unpickle(
                entry.payload, list(zip(entry.places, places, strict=True))
            )
        except Exception as e:  # a class gone from the code, a damaged pickle: never fatal
            self._ignore(f"cannot be read back ({type(e).__name__}: {e})")
            return None
        write_files(temp_dir, made)
        self._touch()
        self.debug(
            f"the plan of {path} from {self.file} ({entry.inputs} inputs unchanged;"
            f" {_ms(self._elapsed())})"
        )
        return Cached(path, plan, options, labels)

    def _read(self) -> bytes | None:
        problem = self._private_folder(make=False)
        if problem:
            if os.path.isdir(self.folder):
                self._ignore(problem, remove=False)
            else:
                self.debug("no entry yet")
            return None
        data, problem = read_private(self.file, MAX_ENTRY_BYTES)
        if data is None:
            if not problem:
                self.debug("no entry yet")
            else:  # what is not the user's own is left; what is broken goes
                broken = problem == "too large" or problem.startswith("cannot be opened")
                self._ignore(problem, remove=broken)
        return data

    def _ignore(self, why: str, remove: bool = True) -> None:
        self._say(f"mlaunch: plan cache: ignored {self.file}: {why}; resolving the launch again")
        if remove:
            try:
                os.unlink(self.file)
            except OSError:
                pass

    def _touch(self) -> None:
        """Mark the entry used (the least recently used go first when the folder is full)."""
        try:
            os.utime(self.file)
        except OSError:
            pass

    # --- writing ------------------------------------------------------------------------------

    def record(self, temp_dir: str) -> plan_inputs.record:
        """What loading and resolving read (``with cache.record(...) as recording:``)."""
        return plan_inputs.record((temp_dir,))

    def store(
        self,
        recording: plan_inputs.Recording,
        path: str,
        plan: Plan,
        options: ResolveOptions,
        labels: LabelCounter,
        places: tuple[str, ...],
    ) -> bool:
        """Write the entry of this resolution; False (``why_not`` says why) when it cannot be.
        ``places``: the run's temp folder (its params files are kept), log folder and run id,
        which a later run's replace wherever the plan names them."""
        self.why_not = ""
        resolved = self._elapsed()
        if recording.refusals:
            self.why_not = "; ".join(recording.refusals)
        else:
            try:
                made = _made_files(places[0])
                value = (path, plan, options, labels, made)
                payload = _pickle(value, places)
            except Exception as e:
                self.why_not = _unpicklable(e)
            else:
                header = {
                    "key": self.key,
                    "inputs": recording.inputs.as_data(),
                    "places": list(places),
                }
                self.why_not = self._write(_join(header, payload))
                if not self.why_not:
                    self.inputs_data = header["inputs"]
        if self.why_not:
            self.debug(f"not stored: {self.why_not}")
            return False
        done = self._elapsed()
        stored = (done[0] - resolved[0], done[1] - resolved[1])
        self.debug(
            f"stored {self.file} ({len(recording.inputs)} inputs; loaded and resolved in"
            f" {_ms(resolved)}; stored in {_ms(stored)})"
        )
        return True

    def _write(self, data: bytes) -> str:
        """Write the entry atomically in the private folder; why not, or ""."""
        if len(data) > MAX_ENTRY_BYTES:
            return f"the plan takes {len(data) >> 20} MiB, more than {MAX_ENTRY_BYTES >> 20}"
        problem = self._private_folder()
        if problem:
            return problem  # said with --debug: a home folder that cannot be written is common
        problem = write_private(self.file, data)
        if problem:
            return problem
        self._prune()
        return ""

    def _private_folder(self, make: bool = True) -> str:
        """Make the folder (0700) when missing; why it cannot hold plans, or ""."""
        import stat

        try:
            if make:
                os.makedirs(self.folder, mode=0o700, exist_ok=True)
            st = os.stat(self.folder)
        except OSError as e:
            return f"cannot make {self.folder}: {e.strerror or e}"
        if st.st_uid != os.getuid():
            return f"{self.folder} is not yours"
        if st.st_mode & 0o077:
            return f"{self.folder} has mode {stat.S_IMODE(st.st_mode):o} (want 700)"
        return ""

    def _prune(self) -> None:
        """Remove the least recently used entries until the folder holds ``limit`` bytes."""
        entries = []
        try:
            with os.scandir(self.folder) as found:
                for entry in found:
                    if entry.name.endswith((".plan", QUICK, ".tmp")) and entry.is_file():
                        st = entry.stat()
                        entries.append((st.st_mtime_ns, st.st_size, entry.path))
        except OSError:
            return
        total = sum(size for _, size, _ in entries)
        for _, size, path in sorted(entries):
            if total <= self.limit:
                break
            try:
                os.unlink(path)
            except OSError:
                pass
            total -= size


def _ms(elapsed: tuple[int, int]) -> str:
    return f"{elapsed[0]} ms, CPU {elapsed[1]} ms"


# --- the entry's bytes ---------------------------------------------------------------------------


def _join(header: dict[str, Any], payload: bytes) -> bytes:
    """FORMAT, the digest of what follows, the header's length, the header (marshal: plain
    data only), the pickled plan."""
    import marshal

    head = marshal.dumps(header)
    body = b"%d\n" % len(head) + head + payload
    return FORMAT + plan_inputs.digest(body).encode("ascii") + b"\n" + body


def _split(data: bytes) -> tuple[dict[str, Any], bytes]:
    """(header, payload) of an entry whose format and digest are right; ValueError otherwise."""
    import marshal

    if not data.startswith(FORMAT):
        raise ValueError("not an entry of this version")
    start = len(FORMAT)
    digest = data[start : start + _DIGEST_CHARS].decode("ascii", "replace")
    body = data[start + _DIGEST_CHARS + 1 :]
    if plan_inputs.digest(body) != digest:
        raise ValueError("its digest does not match")
    size, _, rest = body.partition(b"\n")
    if not size.isdigit():
        raise ValueError("no header")
    header = marshal.loads(rest[: int(size)])
    if not isinstance(header, dict):
        raise ValueError("the header is not a table")
    return header, rest[int(size) :]


def _pickle(value: object, folders: tuple[str, ...]) -> bytes:
    """``value`` pickled; what it holds must be importable by a new run (not launch-file code,
    which pickle names ``python_launch_file``); strings naming ``folders`` (the run's places)
    are written as references, rebased when read back."""
    import io

    buffer = io.BytesIO()
    _ModulesPickler(buffer, tuple(f for f in folders if f)).dump(value)
    return buffer.getvalue()


def _unpickle(
    payload: bytes, places: list[tuple[str, str]]
) -> tuple[str, Plan, ResolveOptions, LabelCounter, dict[str, bytes]]:
    """What ``store`` pickled, with the old run's places in every string that names them
    replaced by this run's."""
    import io

    replacements = [(old, new) for old, new in places if old and old != new]
    replacements.sort(key=lambda pair: -len(pair[0]))

    texts: dict[bytes, str] = {}

    class Unpickler(pickle.Unpickler):
        def persistent_load(self, pid: Any) -> Any:
            kind, data = pid
            if data in texts:
                return texts[data]
            if kind != "folder" or not isinstance(data, bytes):
                raise pickle.UnpicklingError(f"unknown reference {kind!r}")
            text = data.decode("utf-8", "surrogatepass")
            for old, new in replacements:
                text = text.replace(old, new)
            texts[data] = text
            return text

    loaded = Unpickler(io.BytesIO(payload)).load()
    path, plan, options, labels, made = loaded
    return path, plan, options, labels, made


class _Unpicklable(Exception):
    pass


def _unpicklable(error: Exception) -> str:
    if isinstance(error, _Unpicklable):
        return str(error)
    return f"the plan holds what cannot be stored ({type(error).__name__}: {error})"


def _made_files(temp_dir: str) -> dict[str, bytes]:
    """The files resolving wrote in the run's temp folder (params files), by relative path."""
    made: dict[str, bytes] = {}
    if not temp_dir or not os.path.isdir(temp_dir):
        return made
    for folder, _dirs, names in os.walk(temp_dir):
        for name in names:
            full = os.path.join(folder, name)
            if os.path.islink(full):
                raise _Unpicklable(f"resolving left a link in the run's folder: {full}")
            with open(full, "rb") as f:
                made[os.path.relpath(full, temp_dir)] = f.read()
    return made


class _ModulesPickler(pickle.Pickler):
    """A pickler that refuses what a new run could not import, and writes every string that
    names the run's places (temp and log folders, run id) as a reference, rebased when read
    back. Called for every object of the plan: the common cases return first."""

    def __init__(self, file: Any, folders: tuple[str, ...]) -> None:
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.folders = folders
        self.shortest = min((len(f) for f in folders), default=1 << 30)
        self.pids: dict[str, tuple[str, bytes]] = {}

    def persistent_id(self, obj: Any) -> Any:
        kind = type(obj)
        if kind is str:
            if len(obj) < self.shortest:
                return None
            for place in self.folders:
                if place in obj:
                    # bytes: the pid's own items go through persistent_id again; one tuple
                    # per text, so the pickle's memo writes each once
                    pid = self.pids.get(obj)
                    if pid is None:
                        pid = self.pids[obj] = ("folder", obj.encode("utf-8", "surrogatepass"))
                    return pid
            return None
        if kind is FunctionType or isinstance(obj, type):
            module = getattr(obj, "__module__", None)
            if module == "python_launch_file" or module == "__main__":
                name = getattr(obj, "__qualname__", repr(obj))
                raise _Unpicklable(f"the plan holds {name}, defined in the launch file")
        return None
