"""Readiness of a running launch, for a supervisor (systemd's notify) and ``ctl wait-ready``.

Ready means what ``mlaunch test`` means (mlaunch.smoke.watch's SmokeRun with the same
expectations): every process up, named nodes in the graph, lifecycle nodes active, /clock under
simulated time, the file's own expectations. ``ReadyWatch`` is that watch without the test's
end: when ready or failed the launch goes on; it only says so. ``Readiness`` is the part that
owns one and speaks systemd's notify protocol when a notifier is given: STATUS= as checks are met,
READY=1 once ready, WATCHDOG=1 while healthy, STOPPING=1 when the launch begins to shut down.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from mlaunch.engine.part import Part
from mlaunch.plan.records import Record, ShutdownBegun
from mlaunch.smoke.settings import Settings
from mlaunch.smoke.watch import SmokeRun

if TYPE_CHECKING:
    from mlaunch.parts.lifecycle import LifecycleManager
    from mlaunch.parts.sd_notify import Notifier
    from mlaunch.smoke.expectations import Expectation
    from mlaunch.smoke.watch import CheckedRun

# STATUS= is sent at most this often while coming up (on a change).
STATUS_PERIOD = 0.5


class ReadyWatch(SmokeRun):
    """A SmokeRun that never ends the launch: ``ready`` once every check is met, ``failed``
    (the reason) once one cannot be met any more or a process it watches died."""

    def __init__(
        self,
        supervisor: CheckedRun,
        expectations: list[Expectation],
        *,
        lifecycle: LifecycleManager | None = None,
        on_change: Callable[[], None] | None = None,
    ) -> None:
        self.ready = False
        self.ready_at: float | None = None
        self.failed = ""
        self.on_change = on_change
        # No overall deadline: a supervisor's start timeout (or the caller's) is the limit.
        settings = Settings(timeout=float("inf"), hold=0.0)
        super().__init__(supervisor, expectations, settings, lifecycle=lifecycle)

    SOURCE = "ready"

    def seed(self, logs: Callable[[str], list[str]] | None = None) -> None:
        """Attached after the run began: the processes started (and ended) so far, and their
        last lines of output (``logs(label)``) for the output checks. Times count from the
        first process's start, as they would had the watch been there."""
        starts = [p.started_at for p in self.supervisor.processes]
        if starts:
            self.started_at = min(starts)
        for process in list(self.supervisor.processes):
            if logs is not None:
                lines = logs(process.label)
                if lines:
                    self._on_output(process.label, "\n".join(lines).encode())
            self._on_process(False, process)
            if not process.running and process.returncode is not None:
                self._on_process(True, process)

    def _held(self) -> None:
        self.ready = True
        self.ready_at = self.elapsed()
        if self.on_change is not None:
            self.on_change()

    def _finish(self, reason: str) -> None:
        if self.phase == "done":
            return
        self.phase = "done"
        self.failed = reason.removeprefix("mlaunch test failed: ") or reason
        self._stop.set()
        if self.on_change is not None:
            self.on_change()

    def checks(self) -> list[Expectation]:
        return [e for e in self.expectations if e.kind != "shutdown"]

    def summary(self) -> str:
        """One line: where the launch is on its way to ready."""
        checks = self.checks()
        met = sum(1 for e in checks if e.status == "met")
        if self.failed:
            return f"not ready: {self.failed}"
        if self.ready:
            return f"ready: {met} checks met after {self.ready_at or 0:.1f} s"
        waiting = next((e for e in checks if e.status == "pending"), None)
        what = f"; waiting for {waiting.describe()}" if waiting is not None else ""
        return f"starting: {met} of {len(checks)} checks met{what}"

    def state(self) -> dict[str, object]:
        """The answer to ``wait-ready``: ready, failed and each check with its state."""
        return {
            "ready": self.ready and not self.failed,
            "failed": self.failed or None,
            "summary": self.summary(),
            "elapsed": round(self.elapsed(), 3),
            "checks": [
                {
                    "check": e.kind,
                    "target": e.target,
                    "description": e.describe(),
                    "state": e.status,
                    "seen": e.seen,
                    "source": e.origin,
                }
                for e in self.checks()
            ],
        }


class Readiness(Part):
    """Owns the run's ReadyWatch; with a notifier, tells systemd how the launch is doing."""

    def __init__(
        self,
        supervisor: CheckedRun,
        expectations: list[Expectation],
        *,
        notifier: Notifier | None = None,
        lifecycle: LifecycleManager | None = None,
        logs: Callable[[str], list[str]] | None = None,
    ) -> None:
        self.supervisor = supervisor
        self.notifier = notifier
        self._last_status = ""
        self._sent_ready = False
        self.watch = ReadyWatch(
            supervisor, expectations, lifecycle=lifecycle, on_change=self._changed
        )
        self.watch.seed(logs)
        supervisor.records.subscribe(self._on_record)
        if notifier is not None:
            self._status()
            supervisor.schedule(STATUS_PERIOD, self._tick, keeps_alive=False)
            if notifier.watchdog_usec > 0:
                supervisor.schedule(self._watchdog_period(), self._watchdog, keeps_alive=False)

    def state(self) -> dict[str, object]:
        return self.watch.state()

    def _changed(self) -> None:
        if self.notifier is None:
            return
        if self.watch.ready and not self.watch.failed and not self._sent_ready:
            self._sent_ready = True
            self.notifier.ready(self.watch.summary())
            self._last_status = self.watch.summary()
        else:
            self._status()

    def _status(self) -> None:
        assert self.notifier is not None
        text = self.watch.summary()
        if text != self._last_status:
            self._last_status = text
            self.notifier.status(text)

    def _tick(self) -> None:
        if self.supervisor.shutting_down:
            return
        self._status()
        self.supervisor.schedule(STATUS_PERIOD, self._tick, keeps_alive=False)

    def _watchdog_period(self) -> float:
        assert self.notifier is not None
        return max(0.05, self.notifier.watchdog_usec / 2e6)

    def _watchdog(self) -> None:
        """WATCHDOG=1 while healthy: before ready (systemd counts from the start) and after,
        until a watched process dies or a check fails; then no more pings."""
        assert self.notifier is not None
        if self.watch.failed or self.supervisor.shutting_down:
            return
        self.notifier.watchdog()
        self.supervisor.schedule(self._watchdog_period(), self._watchdog, keeps_alive=False)

    def _on_record(self, record: Record) -> None:
        if isinstance(record, ShutdownBegun) and self.notifier is not None:
            reason = record.reason or "shutting down"
            self.notifier.stopping(f"stopping: {reason}")
            self._last_status = "stopping"

    def close(self) -> None:
        self.supervisor.records.unsubscribe(self._on_record)
        self.watch.close()
        if self.notifier is not None:
            self.notifier.close()
