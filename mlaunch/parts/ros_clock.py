"""The ROS clock part: ROSTimer periods on simulated time, counted on /clock.

Under SetUseSimTime(True) launch_ros counts a ROSTimer's period on the clock of launch's own
ROS node, which then follows /clock (rosgraph_msgs/msg/Clock, from a simulator or a bag
player). The engine hands such a wait over (``SimTimeWait``); this part reads /clock through a
private RosGraph (mlaunch.parts.bridge), started on a worker thread at the first wait. A wait
ends once /clock reaches the time it had when the wait began plus the period; before any
message that time is 0, as rclpy's clock under use_sim_time reads (so a first message far
ahead ends every wait begun before it, as launch_ros's timers fire).

The /clock messages arrive on the graph's thread, which only compares the newest time with the
earliest deadline; what is due runs in the supervisor's loop (``LoopCall``). A wait keeps the
launch running (``Supervisor.busy``); at shutdown the waits that cancel on shutdown are dropped.
If the graph cannot start, that is said and the waits left count wall-clock time instead.
"""

from __future__ import annotations

import math
import os
import threading

from mlaunch.engine.part import Part
from mlaunch.parts.handoff import LoopCall, SharedGraph
from mlaunch.plan.records import Record, Said, ShutdownBegun, SimTimeWait

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any, Protocol

    from mlaunch.engine.part import AttachedRun

    class ClockedRun(AttachedRun, Protocol):
        """What the ROS clock part uses of the run (the Supervisor is one): work that keeps an idle
        run alive (a wait on /clock)."""

        def busy(self, work: object) -> None: ...

        def done(self, work: object) -> None: ...

    from mlaunch.parts.graph_types import TopicWatch


class _Wait:
    """One handed-over wait: when it ends (simulated seconds) and what it runs then."""

    __slots__ = ("due", "step")

    def __init__(self, step: SimTimeWait, due: float) -> None:
        self.step = step
        self.due = due


class SimTimeWaits(Part):
    """Takes every ``SimTimeWait`` handed over and ends it when /clock says so."""

    def __init__(self, supervisor: ClockedRun) -> None:
        self.supervisor = supervisor
        self.loop = LoopCall(supervisor.selector)
        self.graph = SharedGraph(dict(os.environ), f"_mlaunch_clock_{os.getpid()}")
        self._lock = threading.Lock()  # ``_now`` and ``_next_due``, read by the graph thread
        self._waits: list[_Wait] = []
        self._now = 0.0  # the newest /clock time, in seconds
        self._next_due = math.inf
        self._watch: TopicWatch | None = None
        self._starting = False
        supervisor.records.subscribe(self.on_record)

    def on_record(self, record: Record) -> None:
        if isinstance(record, SimTimeWait):
            record.taken = True
            self._begin(record)
        elif isinstance(record, ShutdownBegun):
            for wait in [w for w in self._waits if w.step.cancel_on_shutdown]:
                self._forget(wait)

    def _begin(self, step: SimTimeWait) -> None:
        with self._lock:
            wait = _Wait(step, self._now + step.period)
            self._waits.append(wait)
            self._next_due = min(self._next_due, wait.due)
        self.supervisor.busy(wait)
        if not self._starting:
            self._starting = True
            threading.Thread(
                target=self._start_graph, name="mlaunch-ros-clock", daemon=True
            ).start()
        self._end_due()  # a period of 0 ends at once

    def _start_graph(self) -> None:
        """Worker thread: the graph and its /clock watch (a second or so of rclpy start-up)."""
        try:
            watch = self.graph.get().clock()
        except Exception as e:
            error = e  # the name ``e`` is gone once the except block ends
            self.loop.call_soon(lambda: self._unreadable(error))
            return
        self._watch = watch
        watch.listen(self._on_clock)

    def _on_clock(self) -> None:
        """Graph thread: note the newest time; the loop ends what is due."""
        watch = self._watch
        message = watch.last_message() if watch is not None else None
        if message is None:
            return
        now = clock_seconds(message)
        with self._lock:
            self._now = now
            due = now >= self._next_due
        if due:
            self.loop.call_soon(self._end_due)

    def _end_due(self) -> None:
        """Loop thread: run every wait whose time has come, earliest first."""
        with self._lock:
            now = self._now
            due = sorted((w for w in self._waits if w.due <= now), key=lambda w: w.due)
        for wait in due:
            self._forget(wait)
            wait.step.expire()

    def _forget(self, wait: _Wait) -> None:
        with self._lock:
            if wait not in self._waits:
                return
            self._waits.remove(wait)
            self._next_due = min((w.due for w in self._waits), default=math.inf)
        self.supervisor.done(wait)

    def _unreadable(self, error: BaseException) -> None:
        """Loop thread: /clock cannot be read; the waits left count wall-clock time."""
        self.supervisor.records.emit(
            Said(
                "WARNING",
                "launch",
                f"ROSTimer: /clock cannot be read ({error}); the timers on simulated time count"
                " wall-clock time instead",
            )
        )
        for wait in list(self._waits):
            self._forget(wait)
            self.supervisor.schedule(wait.step.period, wait.step.expire)

    def close(self) -> None:
        self.supervisor.records.unsubscribe(self.on_record)
        for wait in list(self._waits):
            self._forget(wait)
        self.loop.close()
        self.graph.close()


def clock_seconds(message: Any) -> float:
    """The time a rosgraph_msgs/Clock message carries, in seconds."""
    return float(message.clock.sec + message.clock.nanosec * 1e-9)
