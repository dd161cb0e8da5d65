"""run(plan) -> exit code: start processes, stream their output, fire triggers, stop everything.

One thread, one ``selectors`` loop. Signal handlers only record the signal (and wake the loop
through ``signal.set_wakeup_fd``); the loop acts on them. Every child runs in its own session, so
the stop ladder (SIGINT, then SIGTERM after sigterm_timeout, then SIGKILL after sigkill_timeout)
reaches its whole process group, and mlaunch is the children's subreaper, so grandchildren that
escape into sessions of their own still come back to it and are ended before it exits.
"""

from __future__ import annotations

import heapq
import itertools
import os
import selectors
import signal
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from mlaunch import events as ev
from mlaunch.errors import MlaunchError
from mlaunch.output import Printer
from mlaunch.plan import (
    AddHandler,
    Deferred,
    EmitEvent,
    Log,
    Plan,
    ProcessSpec,
    RemoveHandler,
    RequestShutdown,
    Spawn,
    StartTimer,
    Step,
)
from mlaunch.process import Process, describe_status, signal_name
from mlaunch.resolve import LabelCounter, ResolveOptions, resolve_deferred

EXIT_OK = 0
EXIT_REQUIRED_FAILED = 1
EXIT_LAUNCH_ERROR = 2
# A crash loop's backoff starts over once a process has stayed up this long.
STABLE_UPTIME = 10.0
# How long an escaped descendant gets between SIGTERM and SIGKILL at shutdown.
STRAY_GRACE = 2.0
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@dataclass(order=True)
class _Timer:
    when: float
    seq: int
    callback: Callable[[], None] = field(compare=False)
    keeps_alive: bool = field(default=True, compare=False)
    cancel_on_shutdown: bool = field(default=True, compare=False)
    cancelled: bool = field(default=False, compare=False)


@dataclass
class Summary:
    """What happened to one process over the run (for the exit table)."""

    label: str
    returncode: int | None = None
    restarts: int = 0
    run_time: float = 0.0
    peak_rss: int = 0
    signals: list[int] = field(default_factory=list)


class Supervisor:
    """Runs a Plan. Seams (printer, clock) are constructor arguments."""

    def __init__(
        self,
        plan: Plan,
        printer: Printer,
        *,
        options: ResolveOptions | None = None,
        labels: LabelCounter | None = None,
        clock: Callable[[], float] = time.monotonic,
        install_signals: bool = True,
    ) -> None:
        self.plan = plan
        self.printer = printer
        self.options = options or ResolveOptions()
        self.labels = labels or LabelCounter()
        self.clock = clock
        self.install_signals = install_signals
        self.selector = selectors.DefaultSelector()
        self.by_pid: dict[int, Process] = {}
        self.processes: list[Process] = []
        self.lingering: list[Process] = []
        self.handlers: list[AddHandler] = []
        self.summaries: dict[str, Summary] = {}
        self._timers: list[_Timer] = []
        self._seq = itertools.count()
        self._signals: list[int] = []
        self._index = itertools.count()
        self.shutting_down = False
        self.shutdown_reason = ""
        self.exit_code = EXIT_OK
        self._stop_presses = 0
        self._wake_r = self._wake_w = -1
        self._subreaper = False
        self.event_hooks: dict[type, Callable[[Any], None]] = {}
        self.listeners: list[Callable[[str, Process], None]] = []
        self._stray_seen: dict[int, float] = {}
        self._stray_signalled: set[tuple[int, int]] = set()

    # --- the loop ------------------------------------------------------------------------------

    def run(self) -> int:
        self._setup_signals()
        try:
            for warning in self.plan.warnings:
                self.printer.message("WARNING", "launch", warning)
            self.execute(self.plan.steps)
            self._become_subreaper()
            while not self._finished():
                self._loop_once()
            self._sweep_descendants()
        finally:
            self._restore_signals()
            self.printer.flush()
        return self.exit_code

    def _loop_once(self) -> None:
        timeout = self._next_timeout()
        if timeout is None or timeout > 0:
            self.printer.flush()
        ready = self.selector.select(timeout)
        for key, _ in ready:
            key.data(key.fd)
        self._handle_signals()
        self._run_due_timers()

    def _finished(self) -> bool:
        if any(p.running for p in self.processes):
            return False
        if not self.shutting_down:
            if any(t.keeps_alive and not t.cancelled for t in self._timers):
                return False
            # Idle: nothing runs and nothing is pending, as ROS 2's idle shutdown.
            self.begin_shutdown("idle")
        if any(p.check_group() for p in self.lingering):
            return False
        if self._strays_pending():
            return False
        for process in self.processes:
            for fd in list(process.streams):
                self._readable(process, fd)
                if fd in process.streams:
                    self.selector.unregister(fd)
                    process.close_stream(fd)
        return True

    def _strays_pending(self) -> bool:
        """Descendants that left their group (setsid) are still ours as subreaper: end them.

        SIGTERM first, SIGKILL after STRAY_GRACE seconds; True while any is alive.
        """
        if not self._subreaper:
            return False
        strays = self._stray_descendants()
        if not strays:
            return False
        now = self.clock()
        for proc in strays:
            first = self._stray_seen.setdefault(proc.pid, now)
            sig = signal.SIGKILL if now - first >= STRAY_GRACE else signal.SIGTERM
            if (proc.pid, sig) in self._stray_signalled:
                continue
            self._stray_signalled.add((proc.pid, sig))
            try:
                name = proc.name()
                proc.send_signal(sig)
            except Exception:
                continue
            self.printer.message(
                "WARNING",
                "launch",
                f"ending stray descendant {name} [pid {proc.pid}] with {signal_name(sig)}",
            )
        return True

    def _stray_descendants(self) -> list[Any]:
        try:
            import psutil
        except ImportError:
            return []
        try:
            children = psutil.Process().children(recursive=True)
        except psutil.Error:
            return []
        out = []
        for child in children:
            try:
                if child.status() != psutil.STATUS_ZOMBIE:
                    out.append(child)
            except psutil.Error:
                continue
        return out

    def _next_timeout(self) -> float | None:
        while self._timers and self._timers[0].cancelled:
            heapq.heappop(self._timers)
        polling = bool(self.lingering or self._stray_seen)
        if not self._timers:
            return 0.05 if polling else None
        delay = max(0.0, self._timers[0].when - self.clock())
        return min(delay, 0.05) if polling else delay

    def schedule(
        self,
        delay: float,
        callback: Callable[[], None],
        *,
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> _Timer:
        timer = _Timer(
            self.clock() + delay, next(self._seq), callback, keeps_alive, cancel_on_shutdown
        )
        heapq.heappush(self._timers, timer)
        return timer

    def _run_due_timers(self) -> None:
        now = self.clock()
        while self._timers and self._timers[0].when <= now:
            timer = heapq.heappop(self._timers)
            if not timer.cancelled:
                timer.cancelled = True
                timer.callback()

    # --- plan steps ------------------------------------------------------------------------------

    def execute(self, steps: list[Step]) -> None:
        for step in steps:
            if isinstance(step, Spawn) and step.spec is not None:
                self.start(step.spec)
            elif isinstance(step, Log):
                self.printer.message(step.level, step.source, step.message)
            elif isinstance(step, StartTimer) and step.body is not None:
                body = step.body
                self.schedule(
                    step.period,
                    lambda body=body: self.fire(body, None),  # type: ignore[misc]
                    cancel_on_shutdown=step.cancel_on_shutdown,
                )
            elif isinstance(step, AddHandler):
                self.handlers.insert(0, step)  # newest first, as ROS 2
            elif isinstance(step, RemoveHandler):
                self.handlers = [h for h in self.handlers if h.handler is not step.handler]
            elif isinstance(step, RequestShutdown):
                self.begin_shutdown(step.reason)
            elif isinstance(step, EmitEvent):
                self.emit(step.event)

    def fire(self, body: Deferred, event: Any) -> None:
        """Resolve deferred entities now (timer, handler, on_exit) and run what they give."""
        try:
            plan = resolve_deferred(body, labels=self.labels, options=self.options, event=event)
        except MlaunchError as e:
            self.printer.message("ERROR", "launch", str(e))
            self.exit_code = max(self.exit_code, EXIT_LAUNCH_ERROR)
            self.begin_shutdown("an event handler failed")
            return
        for warning in plan.warnings:
            self.printer.message("WARNING", "launch", warning)
        self.execute(plan.steps)

    def _dispatch(self, kind: str, process: Process | None, event: Any) -> None:
        for handler in list(self.handlers):
            if handler.kind != kind:
                continue
            if (
                process is not None
                and handler.matcher is not None
                and not handler.matcher(process.spec)
            ):
                continue
            if handler.once:
                self.handlers.remove(handler)
            if handler.body is not None:
                self.fire(handler.body, event)

    def emit(self, event: Any) -> None:
        """Events a launch file emits: ShutdownProcess, SignalProcess, or a hook's (lifecycle)."""
        if isinstance(event, ev.Shutdown):
            self.begin_shutdown(event.reason)
            return
        if isinstance(event, ev.ShutdownProcess):
            for p in self._matching(event.process_matcher):
                self.stop(p)
            return
        if isinstance(event, ev.SignalProcess):
            for p in self._matching(event.process_matcher):
                p.signal_group(int(event.signal_number))
            return
        hook = self.event_hooks.get(type(event))
        if hook is None:
            self.printer.message(
                "WARNING",
                "launch",
                f"event {type(event).__name__} has no handler in mlaunch; ignored",
            )
            return
        hook(event)

    def _matching(self, matcher: Callable[[Any], bool] | None) -> list[Process]:
        return [p for p in self.processes if p.running and (matcher is None or matcher(p))]

    # --- processes ---------------------------------------------------------------------------

    def start(self, spec: ProcessSpec, restarts: int = 0) -> Process | None:
        if self.shutting_down:
            self.printer.message("WARNING", spec.label, "not started: the launch is shutting down")
            return None
        process = Process(spec, index=next(self._index), restarts=restarts)
        self.printer.register(spec.label, process.index)
        if spec.standin and restarts == 0:
            self.printer.message(
                "INFO", spec.label, f"{spec.standin}: not installed, using mlaunch's stand-in"
            )
        try:
            process.spawn(self.clock)
        except OSError as e:
            self.printer.message(
                "ERROR", spec.label, f"failed to start {spec.argv[0]!r}: {e.strerror or e}"
            )
            process.returncode = 127
            self.processes.append(process)
            self._record(process)
            self._after_exit(process)
            return process
        self.processes.append(process)
        self.by_pid[process.pid] = process
        for fd in process.streams:
            self.selector.register(
                fd, selectors.EVENT_READ, lambda fd, p=process: self._readable(p, fd)
            )
        self.printer.message("INFO", spec.label, f"process started with pid [{process.pid}]")
        self._notify("started", process)
        self._dispatch(
            "process_start",
            process,
            ev.ProcessStarted(
                action=spec.action,
                name=spec.label,
                cmd=list(spec.argv),
                cwd=spec.cwd,
                env=spec.env,
                pid=process.pid,
            ),
        )
        return process

    def _readable(self, process: Process, fd: int) -> None:
        stream = process.streams.get(fd)
        if stream is None:
            return
        data, eof = process.read(fd)
        if data:
            self.printer.output(process.label, stream.name, process.spec.output, data)
            if self.handlers:
                self._io_event(process, stream.name, data)
        if eof:
            self.selector.unregister(fd)
            process.close_stream(fd)

    def _io_event(self, process: Process, stream: str, data: bytes) -> None:
        event_type = ev.ProcessStdout if stream == "stdout" else ev.ProcessStderr
        for handler in list(self.handlers):
            if handler.kind != "process_io":
                continue
            if handler.matcher is not None and not handler.matcher(process.spec):
                continue
            callback = handler.io_callbacks.get(stream)
            if callback is None:
                continue
            event = event_type(
                action=process.spec.action,
                name=process.label,
                cmd=list(process.argv),
                pid=process.pid,
                text=data,
                fd=1 if stream == "stdout" else 2,
            )
            result = callback(event)
            if result and handler.body is not None:
                handler.body.entities = list(result)
                self.fire(Deferred(list(result), handler.body.context, handler.body.origin), event)

    def _drain(self, process: Process) -> None:
        """Read what is left in a finished process's pipes before reporting its exit."""
        for fd in list(process.streams):
            for _ in range(64):
                if fd not in process.streams:
                    break
                data, eof = process.read(fd)
                if data:
                    self.printer.output(
                        process.label, process.streams[fd].name, process.spec.output, data
                    )
                if eof:
                    self.selector.unregister(fd)
                    process.close_stream(fd)
                    break
                if not data:
                    break

    def _reap(self) -> None:
        while True:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            process = self.by_pid.pop(pid, None)
            if process is None:
                continue  # an orphaned grandchild we adopted as subreaper
            process.reaped(status, self.clock)
            self._drain(process)
            self._flush_partial(process)
            self._record(process)
            if process.check_group():
                self.lingering.append(process)
            self._after_exit(process)

    def _flush_partial(self, process: Process) -> None:
        """A child that died mid-line: print what it had (a grandchild may keep the pipe open)."""
        for stream in process.streams.values():
            if stream.partial:
                data, stream.partial = stream.partial + b"\n", b""
                self.printer.output(process.label, stream.name, process.spec.output, data)

    def _record(self, process: Process) -> None:
        s = self.summaries.setdefault(process.label, Summary(process.label))
        s.returncode = process.returncode
        s.restarts = process.restarts
        s.run_time += max(0.0, process.ended_at - process.started_at) if process.started_at else 0.0
        s.signals.extend(process.signals_sent)

    def _after_exit(self, process: Process) -> None:
        spec = process.spec
        code = process.returncode if process.returncode is not None else 0
        self._report_exit(process, code)
        self._notify("exited", process)
        event = ev.ProcessExited(
            action=spec.action,
            name=spec.label,
            cmd=list(spec.argv),
            cwd=spec.cwd,
            env=spec.env,
            pid=process.pid,
            returncode=code,
        )
        self._dispatch("process_exit", process, event)
        required = spec.required and not process.stopping
        if required:
            # Before on_exit runs, so the reason names the process rather than the bare
            # Shutdown() its on_exit holds.
            if code != 0:
                self.exit_code = max(self.exit_code, EXIT_REQUIRED_FAILED)
            self.begin_shutdown(f"required process {spec.label} {describe_status(code)}")
        if spec.on_exit is not None:
            self.fire(spec.on_exit, event)
        if not required:
            self._maybe_respawn(process, code)

    def _report_exit(self, process: Process, code: int) -> None:
        label, pid = process.label, process.pid
        if code == 0:
            self.printer.message("INFO", label, f"process has finished cleanly [pid {pid}]")
            return
        if process.stopping and code < 0 and -code in process.signals_sent:
            self.printer.message(
                "INFO", label, f"process stopped by {signal_name(-code)} [pid {pid}]"
            )
            return
        what = describe_status(code)
        if process.core_dumped:
            what += " (core dumped)"
        cmd = " ".join(process.argv)
        self.printer.message(
            "ERROR", label, f"process has died [pid {pid}, exit code {code}, cmd '{cmd}']: {what}"
        )

    def _maybe_respawn(self, process: Process, code: int) -> None:
        policy = process.spec.respawn
        if self.shutting_down or process.stopping or policy.mode == "never":
            return
        if policy.mode == "on-failure" and code == 0:
            return
        if 0 <= policy.max_retries <= process.restarts:
            self.printer.message(
                "ERROR",
                process.label,
                f"giving up after {process.restarts} restarts ({describe_status(code)})",
            )
            return
        uptime = process.ended_at - process.started_at
        streak = getattr(process, "streak", 0)
        streak = 0 if uptime >= STABLE_UPTIME else streak
        delay = min(policy.delay * (policy.backoff**streak), max(policy.max_delay, policy.delay))
        attempt = process.restarts + 1
        limit = "" if policy.max_retries < 0 else f"/{policy.max_retries}"
        self.printer.message(
            "WARNING",
            process.label,
            f"{describe_status(code)}, restart {attempt}{limit} in {delay:.1f} s",
        )

        def again() -> None:
            new = self.start(process.spec, restarts=attempt)
            if new is not None:
                new.streak = streak + 1  # type: ignore[attr-defined]

        self.schedule(delay, again)

    # --- stopping ----------------------------------------------------------------------------

    def begin_shutdown(self, reason: str, *, due_to_signal: int | None = None) -> None:
        if self.shutting_down:
            return
        self.shutting_down = True
        self.shutdown_reason = reason
        if reason != "idle":
            self.printer.message("INFO", "launch", f"shutting down: {reason}")
        for timer in self._timers:
            if timer.cancel_on_shutdown:
                timer.cancelled = True
        self._dispatch(
            "shutdown",
            None,
            ev.Shutdown(reason=reason, due_to_sigint=due_to_signal == signal.SIGINT),
        )
        for process in self.processes:
            if process.running:
                self.stop(process)
        for process in self.lingering:
            if process.check_group() and not process.stopping:
                self.stop(process)

    def stop(self, process: Process) -> None:
        """The ladder for one process group: SIGINT, SIGTERM, SIGKILL, each after its timeout."""
        if process.stopping:
            return
        process.stopping = True
        spec = process.spec
        if not process.signal_group(signal.SIGINT):
            return

        def escalate(sig: int, waited: float, next_step: Callable[[], None] | None) -> None:
            if not (process.running or process.check_group()):
                return
            self.printer.message(
                "WARNING",
                process.label,
                f"failed to terminate {waited:g} s after {signal_name(process.signals_sent[-1])},"
                f" escalating to {signal_name(sig)} [pid {process.pid}]",
            )
            process.signal_group(sig)
            if next_step is not None:
                next_step()

        def to_kill() -> None:
            self.schedule(
                spec.sigkill_timeout,
                lambda: escalate(signal.SIGKILL, spec.sigkill_timeout, None),
                cancel_on_shutdown=False,
            )

        self.schedule(
            spec.sigterm_timeout,
            lambda: escalate(signal.SIGTERM, spec.sigterm_timeout, to_kill),
            cancel_on_shutdown=False,
        )

    def kill_everything(self) -> None:
        """A second Ctrl-C: SIGKILL every group at once."""
        self.printer.message("WARNING", "launch", "stopping now: SIGKILL to every process")
        for process in self.processes + self.lingering:
            if process.running or process.check_group():
                process.stopping = True
                process.signal_group(signal.SIGKILL)
        self._sweep_descendants()

    def _sweep_descendants(self) -> None:
        """End anything still descended from mlaunch (an escaped grandchild) before exiting."""
        if not self._subreaper:
            return
        try:
            import psutil
        except ImportError:
            return
        try:
            strays = psutil.Process().children(recursive=True)
        except psutil.Error:
            return
        strays = [
            p for p in strays if p.pid not in self.by_pid and p.status() != psutil.STATUS_ZOMBIE
        ]
        for stray in strays:
            try:
                name = stray.name()
                stray.kill()
                self.printer.message(
                    "WARNING", "launch", f"killed stray descendant {name} [pid {stray.pid}]"
                )
            except psutil.Error:
                pass
        if strays:
            psutil.wait_procs(strays, timeout=1.0)
        self._reap()

    # --- signals -----------------------------------------------------------------------------

    def _setup_signals(self) -> None:
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)
        self.selector.register(self._wake_r, selectors.EVENT_READ, self._drain_wakeup)
        if not self.install_signals:
            signal.signal(signal.SIGCHLD, self._record_signal)
            signal.set_wakeup_fd(self._wake_w, warn_on_full_buffer=False)
            return
        signal.set_wakeup_fd(self._wake_w, warn_on_full_buffer=False)
        for sig in (*STOP_SIGNALS, signal.SIGCHLD):
            signal.signal(sig, self._record_signal)

    def _record_signal(self, signum: int, frame: object) -> None:
        self._signals.append(signum)

    def _drain_wakeup(self, fd: int) -> None:
        try:
            while os.read(fd, 4096):
                pass
        except BlockingIOError:
            pass

    def _handle_signals(self) -> None:
        while self._signals:
            sig = self._signals.pop(0)
            if sig == signal.SIGCHLD:
                self._reap()
                continue
            self._stop_presses += 1
            if self._stop_presses == 1:
                self.exit_code = max(self.exit_code, 128 + sig)
                self.printer.message(
                    "WARNING",
                    "launch",
                    f"user interrupted with {signal_name(sig)}; stopping (again to kill)",
                )
                self.begin_shutdown(f"{signal_name(sig)} received", due_to_signal=sig)
            else:
                self.kill_everything()
        self._reap()

    def _restore_signals(self) -> None:
        if self.install_signals:
            for sig in (*STOP_SIGNALS, signal.SIGCHLD):
                signal.signal(sig, signal.SIG_DFL)
        else:
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.set_wakeup_fd(-1)
        self.selector.close()
        for fd in (self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass

    def _become_subreaper(self) -> None:
        """Orphaned descendants are re-parented to mlaunch, not to init, so none can escape."""
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            PR_SET_CHILD_SUBREAPER = 36
            self._subreaper = libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
        except (OSError, AttributeError):
            self._subreaper = False

    def _notify(self, what: str, process: Process) -> None:
        for listener in self.listeners:
            listener(what, process)
