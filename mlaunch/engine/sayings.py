"""What mlaunch says about a run's events: the words for each record of the stream.

``Sayings`` turns records (started, exited, escalated, respawn scheduled, ...) into one-line
messages; ``SAYINGS`` says which method says which record. It writes nothing itself: each line
goes to the printer it was made for (mlaunch.engine.output.Printer, which owns the terminal and
the log files and hands it every record that is not a process's output).
"""

from __future__ import annotations

import os

from mlaunch.engine.logfiles import log_file_name
from mlaunch.engine.process import describe_status, signal_name
from mlaunch.plan.records import (
    Controlled,
    Escalated,
    Exited,
    FailedToStart,
    GaveUp,
    HandedOff,
    Interrupted,
    NotStarted,
    Record,
    RespawnScheduled,
    Said,
    ShutdownBegun,
    Started,
    StartsSkipped,
    StoppingAll,
    StrayEnded,
    Unclaimed,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any, Protocol

    from mlaunch.plan.records import ProcessView

    class Saying(Protocol):
        """What the sayings write through (the run's Printer, mlaunch.engine.output)."""

        def message(self, level: str, source: str, text: str, *, always: bool = False) -> None:
            """``[LEVEL] [source]: text``, on screen and in the run's log."""

        def register(self, label: str, index: int) -> None:
            """Prepare a process's prefix and log file."""

        def say_lines_of(self, label: str, start: bytes) -> None:
            """Say ``label``'s stdout lines that begin with ``start`` in every output mode."""


class Sayings:
    """The words for the run's records, said through ``printer``."""

    def __init__(self, printer: Saying) -> None:
        self.printer = printer
        self.message = printer.message
        self._core: tuple[str, bool, int] | None = None  # core_pattern, read at the first crash

    def __call__(self, record: Record) -> None:
        """Say ``record`` (records not in SAYINGS are not said)."""
        method = SAYINGS.get(type(record))
        if method is not None:
            method(self, record)

    def _started(self, event: Started) -> None:
        process = event.process
        spec = process.spec
        self.printer.register(spec.label, process.index)
        if spec.standin and process.restarts == 0:
            self.message(
                "INFO", spec.label, f"{spec.standin}: not installed, using mlaunch's stand-in"
            )
        if spec.announce is not None and process.restarts == 0:
            self.printer.say_lines_of(spec.label, spec.announce)
        self.message("INFO", spec.label, f"process started with pid [{process.pid}]")

    def _failed_to_start(self, event: FailedToStart) -> None:
        spec = event.process.spec
        self.printer.register(spec.label, event.process.index)
        if spec.standin and event.process.restarts == 0:
            self.message(
                "INFO", spec.label, f"{spec.standin}: not installed, using mlaunch's stand-in"
            )
        self.message("ERROR", spec.label, f"failed to start {spec.argv[0]!r}: {event.reason}")

    def _not_started(self, event: NotStarted) -> None:
        self.message("WARNING", event.spec.label, "not started: the launch is shutting down")

    def _starts_skipped(self, event: StartsSkipped) -> None:
        self.message(
            "WARNING",
            "launch",
            f"{event.count} processes not started: the launch is shutting down",
        )

    def _exited(self, event: Exited) -> None:
        process, code = event.process, event.code
        label, pid = process.label, process.pid
        if not pid:
            return  # never started: "failed to start" said it all
        if process.user_stop:
            how = signal_name(-code) if code < 0 else f"exit code {code}"
            why = " for a restart" if process.user_stop == "restart" else ""
            self.message("INFO", label, f"process stopped by the user{why} [pid {pid}, {how}]")
            return
        if code == 0:
            self.message("INFO", label, f"process has finished cleanly [pid {pid}]")
            return
        if process.stopping and process.signals_sent:
            # mlaunch asked it to stop: whatever status its signal handler chose (130, 1, ...)
            # is the answer to that request, not a death.
            if code < 0 and -code in process.signals_sent:
                text = f"process stopped by {signal_name(-code)} [pid {pid}]"
            else:
                sent = signal_name(process.signals_sent[-1])
                text = f"process stopped after {sent} [pid {pid}, exit code {code}]"
            self.message("INFO", label, text)
            return
        what = describe_status(code)
        if process.core_dumped:
            what += " (core dumped)"
        # ROS 2's format; a newline inside an argument (python -c code) is shown escaped so that
        # the message stays one line.
        cmd = " ".join(process.argv).replace("\n", "\\n")
        self.message(
            "ERROR", label, f"process has died [pid {pid}, exit code {code}, cmd '{cmd}']: {what}"
        )
        if code < 0 and not process.stopping:
            hint = self._core_hint(process, -code)
            if hint:
                self.message("INFO", label, hint)

    def _core_hint(self, process: ProcessView, signal_number: int) -> str | None:
        from mlaunch.engine.process import core_dump_hint, core_limit, read_core_pattern

        if self._core is None:
            pattern, uses_pid = read_core_pattern()
            self._core = (pattern, uses_pid, core_limit())
        pattern, uses_pid, limit = self._core
        spec = process.spec
        return core_dump_hint(
            pid=process.pid,
            signal_number=signal_number,
            dumped=process.core_dumped,
            executable="/bin/sh" if spec.shell else spec.argv[0],
            cwd=spec.cwd or os.getcwd(),
            pattern=pattern,
            uses_pid=uses_pid,
            limit=limit,
        )

    def _escalated(self, event: Escalated) -> None:
        process = event.process
        self.message(
            "WARNING",
            process.label,
            f"failed to terminate {event.waited:g} s after "
            f"{signal_name(event.previous) if event.previous else 'the shutdown began'},"
            f" escalating to {signal_name(event.signal)} [pid {process.pid}]",
        )

    def _respawn(self, event: RespawnScheduled) -> None:
        limit = "" if event.max_retries < 0 else f"/{event.max_retries}"
        self.message(
            "WARNING",
            event.process.label,
            f"{describe_status(event.code)}, restart {event.attempt}{limit}"
            f" in {_seconds(event.delay)} s",
        )

    def _gave_up(self, event: GaveUp) -> None:
        self.message(
            "ERROR",
            event.process.label,
            f"giving up after {event.restarts} restarts ({describe_status(event.code)})",
        )

    def _stray(self, event: StrayEnded) -> None:
        self.message(
            "WARNING",
            "launch",
            f"ending stray descendant {event.name} [pid {event.pid}]"
            f" with {signal_name(event.signal)}",
        )

    def _interrupted(self, event: Interrupted) -> None:
        self.message(
            "WARNING",
            "launch",
            f"user interrupted with {signal_name(event.signal)}; stopping (again to kill)",
        )

    def _stopping(self, event: StoppingAll) -> None:
        if event.kill:
            self.message("WARNING", "launch", "stopping now: SIGKILL to every process")

    def _shutdown(self, event: ShutdownBegun) -> None:
        if event.reason != "idle":
            self.message("INFO", "launch", f"shutting down: {event.reason}")

    def _unclaimed(self, event: Unclaimed) -> None:
        record = event.launch_event
        if record.taken:
            return
        if isinstance(record, HandedOff):
            step = record.step
            self.message(
                "ERROR",
                "launch",
                f"{type(step).__name__} ({step.origin}): nothing in this run carries it out"
                f" (it needs {', '.join(sorted(n.value for n in step.needs))}); not done",
            )
            return
        name = type(record.event).__name__
        self.message("WARNING", "launch", f"event {name} has no handler in mlaunch; ignored")

    def _controlled(self, event: Controlled) -> None:
        via = _VIA.get(event.by, "")
        label, action = event.label, event.action
        if action == "mute":
            text = f"output muted by the user{via}; still written to {log_file_name(label)}"
        elif action == "unmute":
            text = f"output unmuted by the user{via}"
        else:
            text = f"{action} asked by the user{via}"
        self.message("INFO", label, text)

    def _said(self, event: Said) -> None:
        self.message(event.level, event.source, event.text)


def _seconds(value: float) -> str:
    """``4.0``, ``0.5``, ``0.05``: one decimal unless that would round a short delay away."""
    return f"{value:.2f}" if 0 < value < 0.1 else f"{value:.1f}"


# How the user's requests came (Controlled.by), in words.
_VIA = {"ctl": " (mlaunch ctl)", "keys": " (--status keys)", "page": " (the launch panel)"}


# Which words each record becomes (records not listed are not said; Output is the Printer's own).
SAYINGS: dict[type, Callable[[Sayings, Any], None]] = {
    Started: Sayings._started,
    FailedToStart: Sayings._failed_to_start,
    NotStarted: Sayings._not_started,
    StartsSkipped: Sayings._starts_skipped,
    Exited: Sayings._exited,
    Escalated: Sayings._escalated,
    RespawnScheduled: Sayings._respawn,
    GaveUp: Sayings._gave_up,
    StrayEnded: Sayings._stray,
    Interrupted: Sayings._interrupted,
    StoppingAll: Sayings._stopping,
    ShutdownBegun: Sayings._shutdown,
    Unclaimed: Sayings._unclaimed,
    Said: Sayings._said,
    Controlled: Sayings._controlled,
}
