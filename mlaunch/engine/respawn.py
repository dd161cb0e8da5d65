"""Respawn: whether a process that exited starts again, and after how long; the run's respawns.

Crash loops back off: the first restart waits ``respawn_delay`` (often 0), and each further exit
within STABLE_UPTIME of starting multiplies the wait by ``respawn_backoff``, up to
``respawn_max_delay``. A process that ran well for a while starts over from the first delay.
"""

from __future__ import annotations

from mlaunch.engine.process_state import GAVE_UP, RESTARTING, STOPPED, ProcessState
from mlaunch.plan.records import GaveUp, RespawnScheduled
from mlaunch.plan.steps import RespawnPolicy

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable

    from mlaunch.engine.process import Process
    from mlaunch.engine.timers import Timer, Timers
    from mlaunch.plan.records import RecordStream
    from mlaunch.plan.steps import ProcessSpec

# A crash loop's backoff starts over once a process has stayed up this long.
STABLE_UPTIME = 10.0
# With respawn_backoff > 1 but no respawn_delay, the backoff grows from this (0 * 2**n is 0).
BACKOFF_BASE = 0.1

# What next_restart decides besides a delay.
NO_RESTART = -1.0
GIVE_UP = -2.0


def respawn_delay(policy: RespawnPolicy, streak: int) -> float:
    """The wait before the next start: ``delay``, then growing by ``backoff`` per quick exit.

    Capped at ``max_delay`` (or ``delay`` if that is larger).
    """
    if streak <= 0 or policy.backoff <= 1.0:
        return policy.delay
    base = policy.delay or BACKOFF_BASE
    cap = max(policy.max_delay, policy.delay)
    return min(base * policy.backoff ** min(streak, 64), cap)


def next_restart(policy: RespawnPolicy, record: ProcessState, code: int, uptime: float) -> float:
    """The delay before restarting a process that exited with ``code`` after ``uptime`` seconds.

    NO_RESTART when the policy does not restart it, GIVE_UP when its retries are spent (restarts
    the user asked for do not count). Updates the record's crash-loop streak (the exponent of
    the backoff).
    """
    if policy.mode == "never" or (policy.mode == "on-failure" and code == 0):
        return NO_RESTART
    if 0 <= policy.max_retries <= record.restarts - record.user_starts:
        return GIVE_UP
    if uptime >= STABLE_UPTIME:
        record.streak = 0  # it ran well for a while: not a crash loop
    delay = respawn_delay(policy, record.streak)
    record.streak += 1
    return delay


class Respawns:
    """The respawns of one run: decided after each exit, waited for by label, cancelled or
    hurried by the user (runtime control).

    ``start(spec, restarts)`` starts a spec again (the supervisor's ``start``); ``forget(old)``
    drops an ended instance from the run's list of processes.
    """

    def __init__(
        self,
        *,
        states: dict[str, ProcessState],
        timers: Timers,
        records: RecordStream,
        clock: Callable[[], float],
        start: Callable[[ProcessSpec, int], object],
        forget: Callable[[Process], None],
    ) -> None:
        self.states = states
        self.timers = timers
        self.records = records
        self.clock = clock
        self.start = start
        self.forget = forget
        # Pending respawns by label: a user's stop or start cancels the one waiting.
        self.waiting: dict[str, Timer] = {}

    def after_exit(self, process: Process, code: int, *, shutting_down: bool) -> None:
        """Start ``process`` again if the user asked for a restart, or if its policy says so
        (after its delay), or give up on it."""
        if process.user_stop == "restart":
            if shutting_down:
                self.states[process.label].not_restarting()
            else:
                self.start_again(process)  # at once: no backoff, the user asked for it
            return
        if shutting_down or process.stopping:
            return
        record = self.states[process.label]
        uptime = process.ended_at - process.started_at
        policy = process.spec.respawn
        delay = next_restart(policy, record, code, uptime)
        if delay == NO_RESTART:
            return
        if delay == GIVE_UP:
            record.state = GAVE_UP
            record.outcome = f"gave up after {record.restarts} restarts: {record.outcome}"
            self.records.emit(GaveUp(process, code, record.restarts))
            return
        attempt = record.restarts + 1
        self.records.emit(RespawnScheduled(process, code, attempt, policy.max_retries, delay))
        record.state, record.restart_at = RESTARTING, self.clock() + delay
        self.waiting[process.label] = self.timers.add(delay, lambda: self._due(process, attempt))

    def _due(self, old: Process, attempt: int) -> None:
        """Start the same spec again (same argv, label, temp files); forget the old instance."""
        self.waiting.pop(old.label, None)
        self.forget(old)
        self.start(old.spec, attempt)

    def cancel(self, label: str, outcome: str) -> None:
        """The respawn ``label`` waits for does not happen: it stays down, ``outcome`` says why."""
        self._cancel_timer(label)
        record = self.states[label]
        record.state, record.restart_at, record.outcome = STOPPED, None, outcome

    def start_again(self, old: Process) -> object:
        """Start ``old``'s spec again now, as the user asked.

        It counts as a restart, but not against respawn's ``max_retries``, and respawn's
        crash-loop backoff starts over: the user ended the last run, not a crash. A respawn
        still waiting for its delay is cancelled.
        """
        self._cancel_timer(old.label)
        record = self.states[old.label]
        record.user_starts += 1
        record.streak = 0
        self.forget(old)
        return self.start(old.spec, record.restarts + 1)

    def _cancel_timer(self, label: str) -> None:
        timer = self.waiting.pop(label, None)
        if timer is not None:
            timer.cancelled = True
