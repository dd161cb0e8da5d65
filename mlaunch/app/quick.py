"""The quick start: a repeated ``mlaunch FILE [name:=value ...]`` starts its first processes
before the rest of mlaunch is imported.

The plan cache (mlaunch.app.plan_cache) spares a repeated start the loading and resolving, but
finding and unpickling the plan still needs most of mlaunch imported first: tens of
milliseconds before the first child, against a bare ``Popen`` loop's few. So when a run's plan
is known (resolved, or taken from the cache), a small *quick entry* is written beside the
plan's: the processes the plan starts before anything else happens (argv, environment), keyed
on the raw command line, the working folder, the environment, the user and the interpreter,
with what the resolution read (mlaunch.plan.inputs: files by identity, folder listings, stats)
and the identity of every mlaunch module it used. The next start with the same key, before
importing anything else, checks those and, when every one reads the same, enters the run's
lifeline (signals, guard, marker, private folder, cgroup), starts those processes
(mlaunch.engine.spawning) and carries on as an ordinary run. The supervisor then *adopts* each
one where its plan starts it (the same label, argv, environment and folder): the run goes on
exactly as if it had started them itself; one it does not find in its plan is ended (said).

Only plain runs: no option on the command line, the cache wanted (not ``MLAUNCH_NO_CACHE``);
only a plan without composable nodes, lifecycle nodes, machines or stand-ins, and only its
leading processes that need no working folder, terminal, params file or preparation (the
rest start as always, when the supervisor reaches them). A file of the resolution changed
less than two seconds before the entry is written (mlaunch.plan.inputs.RACY_NS) holds the entry
back for a run. docs/plan-cache.md says more.

This module imports nothing but ``os`` and ``sys`` at first: what it needs on the way to the
first child comes after the entry has been found sound.
"""

from __future__ import annotations

import os
import sys

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence
    from typing import Any

    from mlaunch.engine.lifeline import Lifeline
    from mlaunch.plan.steps import Plan, ProcessSpec

FORMAT = b"mlaunch quick start 3\n"
SUFFIX = ".quick"
MAX_ENTRY_BYTES = 4 << 20
NO_CACHE_ENV = "MLAUNCH_NO_CACHE"
# The run's marker (mlaunch.engine.proctable.MARKER): rebased in every run, never in the key.
MARKER = "MLAUNCH_RUN_ID"
# Variables keyed by their entries, not their order (the ROS wheels' start-up hook writes
# LD_LIBRARY_PATH's entries in a new order in every interpreter): mlaunch.app.plan_cache's too.
REORDERED = ("LD_LIBRARY_PATH",)
_MLAUNCH_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cache_allowed(environ: Mapping[str, str]) -> bool:
    """The environment's say on the plan cache: not ``MLAUNCH_NO_CACHE`` (any value but empty
    and 0)."""
    return environ.get(NO_CACHE_ENV, "") in ("", "0")


def cache_folder(environ: Mapping[str, str]) -> str:
    """Where the plan cache's entries are: the user's cache folder's mlaunch/plans."""
    base = environ.get("XDG_CACHE_HOME") or ""
    if not os.path.isabs(base):  # the XDG rule: a relative value is ignored
        base = os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "mlaunch", "plans")


def read_private(path: str, limit: int) -> tuple[bytes | None, str]:
    """A cache entry's bytes, or (None, why not): "" when there is none; a problem when it is
    not a regular file of this user's, lets others in, or is over ``limit`` bytes."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        return None, ""
    except OSError as e:
        return None, f"cannot be opened ({e.strerror or e})"
    try:
        st = os.fstat(fd)
        if (st.st_mode & 0o170000) != 0o100000 or st.st_uid != os.getuid():
            return None, "not a file of yours"
        if st.st_mode & 0o077:
            return None, f"mode {st.st_mode & 0o7777:o} lets others in"
        if st.st_size > limit:
            return None, "too large"
        chunks = []
        while chunk := os.read(fd, 1 << 20):
            chunks.append(chunk)
        return b"".join(chunks), ""
    finally:
        os.close(fd)


def write_private(path: str, data: bytes) -> str:
    """Write a cache entry atomically (a temporary file of mode 0600 renamed) into its folder,
    which the plan cache made private; why not, or ""."""
    from mlaunch.ros.files import write_all

    temporary = f"{path}.{os.getpid()}.tmp"
    try:
        fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600)
        try:
            write_all(fd, data)
        finally:
            os.close(fd)
        os.replace(temporary, path)
    except OSError as e:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        return f"cannot write {path}: {e.strerror or e}"
    return ""


def eligible(argv: Sequence[str], environ: Mapping[str, str]) -> bool:
    """A command line the quick start may serve: a launch file (or package and file) and
    ``name:=value`` arguments only, the cache wanted, no shell completion."""
    if not argv or "_ARGCOMPLETE" in environ or not cache_allowed(environ):
        return False
    return not any(arg.startswith("-") for arg in argv)


def key(argv: Sequence[str], environ: Mapping[str, str]) -> str:
    """The digest of everything a quick entry is found by (see the module)."""
    from mlaunch.plan.inputs import digest

    parts = (FORMAT, tuple(argv), environment_key(environ), host_key())
    return digest(repr(parts).encode("utf-8", "surrogateescape"))


def environment_key(environ: Mapping[str, str]) -> list[tuple[str, str]]:
    """The environment as a key holds it: every variable but the run id (rebased), the
    REORDERED ones as their sorted entries (this run's values replace them where a plan names
    them)."""
    items = []
    for name, value in sorted(environ.items()):
        if name == MARKER:
            continue
        if name in REORDERED:
            value = os.pathsep.join(sorted(value.split(os.pathsep)))
        items.append((name, value))
    return items


def host_key() -> tuple[object, ...]:
    """What a key holds of where the run is: the working folder, the user and group, the
    computer (name, machine, kernel release) and Python (version, executable, flags, path)."""
    uname = os.uname()
    return (
        os.getcwd(),
        (os.getuid(), os.getgid()),
        (uname.nodename, uname.machine, uname.release),
        (sys.version, sys.executable, sys.flags, list(sys.path)),
    )


class Child:
    """A process the quick start started: what it was started with, and its ends."""

    __slots__ = (
        "argv",
        "cwd",
        "env",
        "how",
        "label",
        "pid",
        "started_at",
        "stderr",
        "stdin",
        "stdout",
    )

    def __init__(
        self,
        label: str,
        argv: tuple[str, ...],
        env: dict[str, str],
        cwd: str | None,
        pid: int,
        fds: tuple[int, int, int],
        started_at: float,
    ) -> None:
        self.label = label
        self.argv = argv
        self.env = env
        self.cwd = cwd
        self.pid = pid
        self.stdin, self.stdout, self.stderr = fds  # our ends: stdin's write end, the reads
        self.started_at = started_at
        self.how = ""  # how it was started, for the run's log: "by the quick start" ...

    @property
    def fds(self) -> tuple[int, int, int]:
        return (self.stdin, self.stdout, self.stderr)

    def difference(self, spec: ProcessSpec, env: Mapping[str, str]) -> str:
        """How ``spec`` (with the run's ``env`` added) differs from what this child was started
        as ("" when it does not)."""
        if spec.label != self.label:
            return f"its label is {spec.label}"
        if _argv(spec) != self.argv:
            return f"its command line is {list(_argv(spec))}"
        if spec.cwd != self.cwd:
            return f"its folder is {spec.cwd}"
        full = {**spec.env, **env}
        names = sorted(n for n in {*full, *self.env} if full.get(n) != self.env.get(n))
        return f"its environment differs in {', '.join(names)}" if names else ""


class Prestart:
    """Children started before the supervisor exists, which it adopts where its plan starts
    them (``take``) or ends (``abandon``); ``life``: the lifeline entered for them, if they
    entered one (the quick start's)."""

    def __init__(self) -> None:
        self.life: Lifeline | None = None
        self.children: dict[str, Child] = {}

    def start_first(self, plan: Plan, life: Lifeline) -> None:
        """Start ``plan``'s leading processes now, before the supervisor and its parts are
        made (their imports and set-up are most of a resolved launch's way to its first
        child); it adopts them as the quick start's. The run's lifeline is settled (mlaunch in
        its cgroup) first, as the supervisor has it before starting anything."""
        from mlaunch.engine import spawning

        if not spawning.AVAILABLE:
            return
        first, _why = _first_processes(plan, life.run_id)
        if not first:
            return
        life.settle()
        # A Ctrl-C now is the supervisor's to act on, as in its own spawn batch: the starts
        # stop, and it gets the signal once its handlers are in (its shutdown then stops what
        # started and says how many did not).
        life.defer_signals()
        try:
            how = "as soon as its plan was known"
            self._start_all(first, life, (), settled=True, how=how, stop=lambda: life.received)
        finally:
            life.pass_signals_on()

    def _start_all(
        self,
        first: list[Any],
        life: Lifeline,
        rebase: Sequence[tuple[str, str]],
        *,
        settled: bool,
        how: str,
        stop: Callable[[], object] | None = None,
    ) -> None:
        """Start ``first`` (as ``_first_processes`` lists them; ``rebase``: old, new texts),
        telling the guard, until one cannot start (the supervisor starts it and says why) or
        ``stop()``. Unless mlaunch was ``settled`` in its cgroup, they are moved in after it."""
        import time

        from mlaunch.engine.spawning import start

        guard = life.guard
        for label, argv, env, cwd, grace in first:
            if stop is not None and stop():
                break
            if rebase:
                argv = [_rebased(arg, rebase) for arg in argv]
                env = {name: _rebased(value, rebase) for name, value in env.items()}
                cwd = None if cwd is None else _rebased(cwd, rebase)
            child = _start(start, label, tuple(argv), env, cwd, time.monotonic)
            if child is None:
                break
            child.how = how
            self.children[label] = child
            if guard is not None:
                guard.watch(child.pid, grace)
        if guard is not None:
            guard.flush()
        if self.children:
            # After them, not before (ctypes costs milliseconds): a daemon among them that
            # forks away while the supervisor is being made is re-parented to mlaunch, whose
            # supervisor finds it (it becomes the subreaper again itself, as in every run).
            from mlaunch.engine.strays import set_subreaper

            set_subreaper(True)
        if life.cgroup is not None and self.children and not settled:
            life.cgroup.move_soon([child.pid for child in self.children.values()])

    def has(self, spec: ProcessSpec) -> bool:
        """Whether a child was started as ``spec``'s label (taken or not yet)."""
        return spec.label in self.children

    def take(self, spec: ProcessSpec, env: Mapping[str, str]) -> Child | None:
        """The child started as ``spec`` (the supervisor adopts it), or None; a child of that
        label started otherwise is ended (its plan changed since the entry was written)."""
        child = self.children.pop(spec.label, None)
        if child is None:
            return None
        difference = child.difference(spec, env)
        if not difference:
            return child
        _end(child, f"the run's plan starts it otherwise ({difference})")
        return None

    def abandon(self, why: str = "its plan does not start it") -> None:
        """End the children no one adopted (said, with ``why``)."""
        children, self.children = self.children, {}
        for child in children.values():
            _end(child, why)

    def close(self) -> None:
        """At the program's end: what the run did not adopt is ended (it ended before it could:
        a bad command line, a signal) and the lifeline left, if the run did not leave it."""
        self.abandon("the run ended before it took it")
        if self.life is not None:
            self.life.__exit__(None, None, None)


class QuickStart(Prestart):
    """One run's quick start: its key, and (when its entry was sound) the lifeline it entered
    and the children it started, which the run adopts or ends (``abandon``)."""

    def __init__(self, argv: Sequence[str], environ: Mapping[str, str]) -> None:
        super().__init__()
        self.argv = tuple(argv)
        self.key = key(argv, environ)
        self.folder = cache_folder(environ)
        self.file = os.path.join(self.folder, self.key + SUFFIX)
        self.found = False  # the entry was sound: its children started (or could not start)
        self.why_not = ""  # why the last plan was not noted ("" when it was)

    # --- the start ------------------------------------------------------------------------------

    def start(self) -> bool:
        """Start the entry's processes when it is sound and its inputs read the same."""
        entry = self._entry()
        if entry is None:
            return False
        self.found = True
        from mlaunch.engine import spawning

        if not spawning.AVAILABLE:
            return False  # this Python's fork_exec is not the one spawning knows: as always
        from mlaunch.engine.lifeline import Lifeline

        life = Lifeline()
        life.__enter__()
        self.life = life
        try:
            self._spawn(entry, life)
        except BaseException as e:  # a signal (the lifeline's Stopped) while starting them
            self.abandon("mlaunch stopped while starting it")
            life.__exit__(type(e), e, e.__traceback__)
            raise
        return True

    def _entry(self) -> dict[str, Any] | None:
        data, _problem = read_private(self.file, MAX_ENTRY_BYTES)
        if data is None or not data.startswith(FORMAT):
            return None  # a bad entry is the plan cache's to say: the ordinary path reads it
        import marshal

        from mlaunch.plan import inputs

        body = data[len(FORMAT) :]
        sealed, _, rest = body.partition(b"\n")
        if sealed.decode("ascii", "replace") != inputs.digest(rest):
            return None
        try:
            entry = marshal.loads(rest)
            if not isinstance(entry, dict) or entry.get("key") != self.key:
                return None
            for path, known in entry["code"]:
                if inputs.identity(path) != known:
                    return None
            if inputs.Inputs.from_data(entry["inputs"]).changed() is not None:
                return None
        except (KeyError, TypeError, ValueError, EOFError):
            return None
        return entry

    def _spawn(self, entry: dict[str, Any], life: Lifeline) -> None:
        # What differs between two runs of the same plan: the run id, the order of the
        # REORDERED variables' entries (the key holds them sorted).
        rebase = [(entry["run_id"], life.run_id)]
        if entry["files"]:
            write_files(life.temp_dir, entry["files"])
            rebase.append((entry["temp_dir"], life.temp_dir))
        for name, old in entry["reordered"].items():
            now = os.environ.get(name, "")
            if old and now and old != now:
                rebase.append((old, now))
        how = "by the quick start, before mlaunch loaded its plan"
        self._start_all(entry["first"], life, rebase, settled=False, how=how)

    # --- the entry ------------------------------------------------------------------------------

    def note(self, plan: Plan, run_id: str, places: tuple[str, str], inputs_data: Any) -> bool:
        """Write the quick entry of ``plan`` (its processes started in the run ``run_id``, whose
        temp and log folders are ``places``; ``inputs_data``: what its resolution read, as the
        plan cache holds it); False (``why_not`` says why) when it has none to write."""
        temp_dir, log_dir = places
        files: dict[str, bytes] = {}
        first, why = _first_processes(plan, run_id, temp_dir, log_dir, files)
        if not first:
            self.why_not = why
            return False
        code = _code_identities()
        if code is None:
            self.why_not = "a file of mlaunch changed moments ago"
            return False
        import marshal
        import time

        from mlaunch.plan import inputs

        inputs_data = _identified(inputs_data)
        if inputs_data is None:
            self.why_not = "a file it read changed moments ago"
            return False
        entry = {
            "key": self.key,
            "code": code,
            "inputs": inputs_data,
            "run_id": run_id,
            "reordered": {name: os.environ.get(name, "") for name in REORDERED},
            "temp_dir": temp_dir,
            "files": files,
            "first": first,
            "made": time.time_ns(),
        }
        rest = marshal.dumps(entry)
        data = FORMAT + inputs.digest(rest).encode("ascii") + b"\n" + rest
        self.why_not = write_private(self.file, data)
        return not self.why_not


def prestart(argv: Sequence[str], environ: Mapping[str, str]) -> QuickStart | None:
    """The quick start of this command line (its children started when its entry is sound),
    or None when the command line is not one it serves."""
    if not eligible(argv, environ):
        return None
    quick = QuickStart(argv, environ)
    quick.start()
    return quick


def _argv(spec: ProcessSpec) -> tuple[str, ...]:
    """What the child's argv is: ROS 2 joins a shell command with spaces for /bin/sh."""
    if spec.shell:
        return ("/bin/sh", "-c", " ".join(spec.argv))
    return tuple(spec.argv)


def _start(
    start: Any,
    label: str,
    argv: tuple[str, ...],
    env: dict[str, str],
    cwd: str | None,
    clock: Any,
) -> Child | None:
    """Start one child (stdin a pipe we keep open, stdout and stderr pipes); None when its
    program cannot be started (the supervisor tries again and says why)."""
    from mlaunch.engine.spawning import with_pipes

    def start_child(stdin: int, out: int, err: int) -> int:
        return int(start(argv, env, cwd=cwd, stdin=stdin, stdout=out, stderr=err))

    try:
        pid, stdin_write, (out_read, err_read) = with_pipes(start_child)
    except (OSError, ValueError):  # out of descriptors, or it cannot start: the supervisor
        return None  # starts it (raising its limit) and says why it cannot
    return Child(label, argv, env, cwd, pid, (stdin_write, out_read, err_read), clock())


def _end(child: Child, why: str) -> None:
    """SIGKILL a child's group, reap it, close our ends; one line on stderr."""
    import signal

    try:
        os.killpg(child.pid, signal.SIGKILL)
    except OSError:
        pass
    try:
        os.waitpid(child.pid, 0)
    except ChildProcessError:
        pass
    for fd in (child.stdin, child.stdout, child.stderr):
        try:
            os.close(fd)
        except OSError:
            pass
    from mlaunch.engine.lifeline import say

    say(f"mlaunch: quick start: ended {child.label} (pid {child.pid}): {why}")


def _identified(inputs_data: Any) -> Any:
    """``inputs_data`` (Inputs.as_data) with an identity for every file it read, so the quick
    start checks each by a stat, never by reading it: a file the plan cache knows by its
    content only (it changed just before that entry was made) gets its identity now, if it is
    settled and still holds that content; None when one is not."""
    import time

    from mlaunch.plan.inputs import RACY_NS, file_digest, identity

    files, listings, probes, unchanged = inputs_data
    missing = [p for p, known in files.items() if known is not None and p not in unchanged]
    if not missing:
        return inputs_data
    unchanged = dict(unchanged)
    settled = time.time_ns() - RACY_NS
    for path in missing:
        before = identity(path)
        if before is None or before[4] >= settled:
            return None
        if file_digest(path) != files[path] or identity(path) != before:
            return None
        unchanged[path] = before
    return (files, listings, probes, unchanged)


def _rebased(text: str, rebase: Sequence[tuple[str, str]]) -> str:
    for old, new in rebase:
        if old in text:
            text = text.replace(old, new)
    return text


def _first_processes(
    plan: Plan,
    run_id: str,
    temp_dir: str = "",
    log_dir: str = "",
    files: dict[str, bytes] | None = None,
) -> tuple[list[Any], str]:
    """The processes ``plan`` starts before anything else happens, as the entry holds them;
    or ([], why there are none). For a quick entry, ``temp_dir`` and ``log_dir`` are the run's
    folders: a process may name a file in the first (a params file: ``files`` gets its bytes,
    by its path in the folder, to be written again in the next run's), never the second."""
    from mlaunch.plan.steps import AddHandler, Log, Spawn, StartTimer

    if plan.needs:
        return [], "the launch needs " + ", ".join(sorted(need.value for need in plan.needs))
    first: list[Any] = []
    for step in plan.steps:
        if isinstance(step, (AddHandler, Log, StartTimer)):
            continue  # nothing a child can see: said or armed once the run is up, as always
        if not isinstance(step, Spawn) or step.spec is None:
            break
        spec = step.spec
        why = _not_quick(spec, temp_dir, log_dir, files)
        if why:
            return first, why
        env = {**spec.env, MARKER: run_id}  # as the supervisor starts it (its marker)
        first.append((spec.label, list(_argv(spec)), env, spec.cwd, spec.sigkill_timeout))
    return first, "the launch starts no process first"


def _not_quick(
    spec: ProcessSpec, temp_dir: str, log_dir: str, files: dict[str, bytes] | None
) -> str:
    """Why the quick start cannot start ``spec`` itself ("" when it can); the run's files it
    names go in ``files``."""
    if spec.emulate_tty:
        return f"{spec.label} wants a terminal"
    if spec.machine is not None or spec.standin or spec.prepare is not None:
        return f"{spec.label} is started otherwise"
    if spec.announce is not None:
        return f"{spec.label} is told what to do on its stdin"
    texts = [*spec.argv, *spec.env.values(), spec.cwd or ""]
    if log_dir and any(log_dir in text for text in texts):
        return f"{spec.label} names the run's log folder"
    if not temp_dir:
        return ""
    # A file of the run's folder it names to the end of an argument (--params-file PATH,
    # __params:=PATH) is written again in the new run's folder; nothing else of the folder.
    named = {}
    for text in texts:
        start = text.find(temp_dir + os.sep)
        if start < 0:
            if temp_dir in text:
                return f"{spec.label} names the run's folder"
            continue
        path = text[start:]
        relative = path[len(temp_dir) + 1 :]
        if ".." in relative.split(os.sep) or temp_dir in relative:
            return f"{spec.label} names the run's folder"
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError:
            return f"{spec.label} names {path}, which cannot be read"
        named[relative] = data
    if files is not None:
        files.update(named)
    return ""


def write_files(folder: str, files: Mapping[str, bytes]) -> None:
    """Write the run's params files (relative path: bytes) into its ``folder`` (0700 folders,
    0600 files); one already there with the same bytes is left (the quick start wrote it)."""
    from mlaunch.ros.files import write_all

    for relative, data in files.items():
        full = os.path.join(folder, relative)
        os.makedirs(os.path.dirname(full), mode=0o700, exist_ok=True)
        try:
            fd = os.open(full, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600)
        except FileExistsError:
            with open(full, "rb") as f:
                if f.read() == data:
                    continue
            raise
        try:
            write_all(fd, data)
        finally:
            os.close(fd)


def _code_identities() -> list[tuple[str, tuple[int, ...] | None]] | None:
    """The identity of every mlaunch module loaded so far and of every folder of mlaunch (a
    module added or removed changes its folder); None when one changed moments ago."""
    import time

    from mlaunch.plan.inputs import RACY_NS, identity

    paths = set()
    for module in list(sys.modules.values()):
        path = getattr(module, "__file__", None)
        if isinstance(path, str) and path.startswith(_MLAUNCH_DIR + os.sep):
            paths.add(path)
    for folder, dirs, _names in os.walk(_MLAUNCH_DIR):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        paths.add(folder)
    settled = time.time_ns() - RACY_NS
    found = []
    for path in sorted(paths):
        known = identity(path)
        if known is not None and known[4] >= settled:
            return None
        found.append((path, known))
    return found
