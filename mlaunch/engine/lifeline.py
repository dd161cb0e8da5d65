"""The whole life of the program, not only the supervisor loop: signals, guard, private folder.

A launch runs code long before its first supervised process: loading a Python launch file runs
it, and resolving runs ``Command`` substitutions and xacro, which may take seconds (and is when
``docker stop`` or systemd's SIGTERM tends to arrive). From the first line of a launch on:

- SIGINT, SIGTERM and SIGHUP unwind the program (``Stopped``, a KeyboardInterrupt, so that
  ``subprocess.run`` kills the command it waits for) with exit status 128+N, once; a second
  signal while unwinding is only recorded, so that the clean-up itself is never cut short;
- the guard is already forked, holding the private folder's path, and every process mlaunch or
  the launch file starts carries the run's marker (``MLAUNCH_RUN_ID``, set in mlaunch's own
  environment for the run), so even ``kill -9`` of mlaunch while loading leaves nothing;
- on any abnormal way out (a signal, a bad launch file) what the load started and left running
  is ended, and the private folder is removed.

While the supervisor's loop runs, its own handlers take over (they record; its loop acts); the
signals are blocked in the short hand-over windows, so none arrives at the wrong handler.

``ensure_std_streams`` makes a closed stdin, stdout or stderr (``mlaunch FILE >&-``) /dev/null,
before anything else opens a file that would take its number.
"""

from __future__ import annotations

import os
import signal
import sys
import time

from mlaunch.engine import guard as guards
from mlaunch.engine import proctable
from mlaunch.engine.privatedir import private_temp_dir, remove_private_dir
from mlaunch.plan.errors import OutputError, exit_for_signal

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.engine.cgroup import RunCgroup

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
# What a process the load left behind gets between SIGTERM and SIGKILL.
LEFTOVER_GRACE = 2.0


class Stopped(KeyboardInterrupt):
    """A stop signal arrived outside the supervisor's loop: unwind, cleaning up on the way.

    A KeyboardInterrupt, so code that cleans up after Ctrl-C (``subprocess.run`` kills its
    child) does the same for SIGTERM and SIGHUP.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum
        self.exit_code = exit_for_signal(signum)


class Lifeline:
    """Signals, guard, marker and private folder for one run of the program (a context manager).

    Entered before the launch file is loaded, even for --print and --show-args: a launch file's
    code and its substitutions may start processes at any of those steps.
    """

    def __init__(self, *, environ: dict[str, str] | os._Environ[str] | None = None) -> None:
        self.environ = os.environ if environ is None else environ
        self.run_id = guards.new_run_id()
        self.temp_dir = ""
        self.guard: guards.Guard | None = None
        self.cgroup: RunCgroup | None = None
        self.no_cgroup = ""  # why the run has no cgroup of its own
        self.received: list[int] = []
        self._raising = True
        self._old_handlers: dict[int, object] = {}
        self._old_marker: str | None = None
        self._entered = False

    def __enter__(self) -> Lifeline:
        if self._entered:  # the quick start entered it (mlaunch.app.quick): the run goes on
            return self
        self._entered = True
        for sig in STOP_SIGNALS:
            self._old_handlers[sig] = signal.signal(sig, self._on_signal)
        self._old_marker = self.environ.get(proctable.MARKER)
        # Inherited by every process started from now on: Command substitutions, a launch
        # file's own subprocesses and their descendants, whatever session they move to.
        self.environ[proctable.MARKER] = self.run_id
        self.temp_dir = private_temp_dir()
        from mlaunch.engine.cgroup import RunCgroup

        self.cgroup, self.no_cgroup = RunCgroup.create(self.environ)
        cgroup_path = self.cgroup.path if self.cgroup is not None else None
        self.guard = guards.Guard.start(self.run_id, temp_dir=self.temp_dir, cgroup=cgroup_path)
        # In after the guard is forked: it must outlive (and kill) the cgroup. The move waits in
        # the kernel for an RCU grace period (2-15 ms, no CPU): a thread makes it while the
        # launch file loads and resolves, and settle() waits for it before the supervisor
        # starts anything. What the launch file's own code or a Command substitution starts in
        # those milliseconds may start outside the cgroup: it carries the run's marker (set
        # above), by which the guard and the stray sweep find it, as in a run without a cgroup.
        if self.cgroup is not None:
            self.cgroup.enter_soon()
        return self

    def settle(self) -> None:
        """Wait until mlaunch is in the run's cgroup (or the run has none, saying why)."""
        if self.cgroup is not None and not self.cgroup.settle():
            self.no_cgroup = f"cannot move into {self.cgroup.path}"
            self.cgroup.remove()
            self.cgroup = None

    def _on_signal(self, signum: int, frame: object) -> None:
        self.received.append(signum)
        if self._raising:
            self._raising = False  # once: the unwinding must not be cut short by a second one
            raise Stopped(signum)

    def defer_signals(self) -> None:
        """From now on a stop signal is only recorded (``received``), until ``pass_signals_on``:
        the supervisor, not made yet, is to act on it (the first processes start before it)."""
        self._raising = False

    def pass_signals_on(self) -> None:
        """Stop signals raise again; the ones recorded since ``defer_signals`` are sent again,
        held in the kernel (blocked, as ``block`` holds them) until the supervisor's handlers
        take them."""
        received, self.received = self.received, []
        if received:
            signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
            for sig in dict.fromkeys(received):
                os.kill(os.getpid(), sig)
        self._raising = True

    def check(self) -> None:
        """Raise ``Stopped`` for a signal that arrived while the code running caught it."""
        if self.received and self._raising:
            self._raising = False
            raise Stopped(self.received[0])

    def block(self) -> None:
        """Hold the stop signals in the kernel until the supervisor has installed its handlers.

        The supervisor unblocks them once its handlers are in, and blocks them again before it
        puts ours back; ``hand_over`` then takes what is pending, only to record it.
        """
        self.check()
        signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)

    def hand_over(self) -> None:
        """The supervisor has run: from now on a stop signal is recorded, not raised."""
        self._raising = False
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)

    def __exit__(self, kind: type[BaseException] | None, error: object, tb: object) -> None:
        if not self._entered:
            return  # left already (the quick start's lifeline, left by the run)
        self._entered = False
        self._raising = False
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
        try:
            self.settle()
            if kind is not None:
                if isinstance(error, Stopped):
                    say(
                        f"mlaunch: stopped by {signal.Signals(error.signum).name}"
                        " before the launch had started"
                    )
                exclude = {self.guard.pid} if self.guard else set()
                end_leftovers(self.run_id, self.cgroup, exclude=exclude)
            if self.cgroup is not None:
                self.cgroup.leave()  # and what a normal run left in it is killed
            if self.temp_dir:
                remove_private_dir(self.temp_dir)
            if self.guard is not None:
                self.guard.close()  # goodbye: mlaunch has ended what it started
        finally:
            if self._old_marker is None:
                self.environ.pop(proctable.MARKER, None)
            else:
                self.environ[proctable.MARKER] = self._old_marker
            for sig, handler in self._old_handlers.items():
                signal.signal(sig, handler)  # type: ignore[arg-type]


def end_leftovers(
    run_id: str, cgroup: RunCgroup | None, *, exclude: set[int], grace: float = LEFTOVER_GRACE
) -> int:
    """SIGTERM (then SIGKILL after ``grace``) what carries the run's marker or is in its cgroup.

    Only on an abnormal way out: a normal run's supervisor has ended everything already.
    Returns how many processes there were.
    """
    me = os.getpid()
    found = {p.pid for p in proctable.marked(run_id)}
    if cgroup is not None:
        found.update(cgroup.members())
    first = [pid for pid in found if pid != me and pid not in exclude]
    for pid in first:
        _send(pid, signal.SIGTERM)
        _send(pid, signal.SIGCONT)
    deadline = time.monotonic() + grace
    while first and time.monotonic() < deadline:
        _reap_any()
        if not any(_alive(pid) for pid in first):
            return len(first)
        time.sleep(0.01)
    for pid in first:
        _send(pid, signal.SIGKILL)
    _reap_any()
    return len(first)


def _alive(pid: int) -> bool:
    info = proctable.proc_info(pid)
    return info is not None and not info.zombie


def _reap_any() -> None:
    """Reap our own exited children (a leftover may be one), never blocking."""
    try:
        while os.waitpid(-1, os.WNOHANG)[0]:
            pass
    except ChildProcessError:
        pass


def _send(pid: int, sig: int) -> None:
    try:
        os.kill(pid, sig)
    except OSError:
        pass


def ensure_std_streams() -> list[str]:
    """Give a closed fd 0, 1 or 2 /dev/null, and Python a stream for it; the names of the Python
    streams (``sys.stdout`` ...) that had none or a closed one.

    Started with stdout closed (``>&-``), the first file mlaunch opens would otherwise get
    fd 1, and the terminal's output would go into it (a log file, the guard's pipe). A launch
    file runs in mlaunch's interpreter and may close ``sys.stdout`` (or fd 1) itself: called
    again after loading and resolving, this gives mlaunch its streams back.
    """
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
            continue
        except OSError:
            pass
        devnull = os.open(os.devnull, os.O_RDWR)
        if devnull != fd:
            os.dup2(devnull, fd)
            os.close(devnull)
    restored = []
    for fd, name in enumerate(("stdin", "stdout", "stderr")):
        stream = getattr(sys, name)
        if stream is not None and not getattr(stream, "closed", False):
            continue
        errors = "backslashreplace" if name == "stderr" else "strict"
        mode = "r" if fd == 0 else "w"
        setattr(sys, name, open(fd, mode, encoding="utf-8", errors=errors, closefd=False))  # noqa: SIM115
        restored.append(name)
    return restored


def say(text: str) -> None:
    """One line on stderr, whatever became of it (closed, a broken pipe)."""
    try:
        sys.stderr.write(text + "\n")
        sys.stderr.flush()
    except (OSError, ValueError, AttributeError):
        pass


def write_stdout(text: str) -> None:
    """All of ``text`` to fd 1, raising BrokenPipeError if the reader goes away.

    sys.stdout is not trusted with this: when the reader leaves in the middle of a large write,
    its buffered layer can report success for the part that never arrived.
    """
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, ValueError, OSError):  # not a file (a test's capture)
        sys.stdout.write(text)
        return
    view = memoryview(text.encode("utf-8", "surrogateescape"))
    try:
        sys.stdout.flush()
        while view:
            view = view[os.write(fd, view) :]
    except BrokenPipeError:
        raise
    except OSError as e:  # /dev/full, a full disk or quota, an I/O error: not mlaunch's bug
        raise OutputError(f"cannot write to standard output: {e.strerror or e}") from None


def stdout_gone() -> int:
    """stdout's reader went away (``mlaunch ... --print | head -1``): end as Unix tools do.

    They die of SIGPIPE, which the shell shows as 141; mlaunch returns that status without a
    traceback, after pointing fd 1 at /dev/null so that the final flush cannot fail again.
    """
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    except OSError:
        pass
    return exit_for_signal(signal.SIGPIPE)
