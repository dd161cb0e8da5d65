"""The supervisor loop's pending callbacks: TimerActions, respawns, stop-ladder steps, refreshes."""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable


class Timer:
    """A pending callback in the loop's heap (a plain class: dataclass creation costs start-up).

    ``keeps_alive`` False: the timer alone does not keep an idle launch running (a status
    refresh); ``cancel_on_shutdown`` False: it still fires while shutting down (the ladder).
    """

    __slots__ = (
        "callback",
        "cancel_on_shutdown",
        "cancelled",
        "holds_shutdown",
        "keeps_alive",
        "seq",
        "when",
    )

    def __init__(
        self,
        when: float,
        seq: int,
        callback: Callable[[], object],
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> None:
        self.when = when
        self.seq = seq
        self.callback = callback
        self.keeps_alive = keeps_alive
        self.cancel_on_shutdown = cancel_on_shutdown
        self.cancelled = False
        # A TimerAction(cancel_on_shutdown=False): the shut-down launch waits for it to fire, as
        # launch waits for its future (the stop ladder's timers do not hold the end).
        self.holds_shutdown = False

    def __lt__(self, other: Timer) -> bool:
        return (self.when, self.seq) < (other.when, other.seq)


class Timers:
    """A heap of Timers on one clock; the loop asks how long it may wait and runs what is due."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self.clock = clock
        self._heap: list[Timer] = []
        self._seq = itertools.count()

    def add(
        self,
        delay: float,
        callback: Callable[[], object],
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> Timer:
        when = self.clock() + delay
        timer = Timer(when, next(self._seq), callback, keeps_alive, cancel_on_shutdown)
        heapq.heappush(self._heap, timer)
        return timer

    def keep_alive(self) -> bool:
        """Whether a pending timer keeps an otherwise idle launch running."""
        return any(t.keeps_alive and not t.cancelled for t in self._heap)

    def hold_shutdown(self) -> bool:
        """Whether a pending timer must fire before a shut-down launch may end."""
        return any(t.holds_shutdown and not t.cancelled for t in self._heap)

    def shutting_down(self) -> None:
        """Cancel what should not fire once the launch shuts down (respawns, TimerActions)."""
        for timer in self._heap:
            if timer.cancel_on_shutdown:
                timer.cancelled = True

    def next_delay(self) -> float | None:
        """Seconds until the next timer is due (0 if one is), None if none is pending."""
        heap = self._heap
        while heap and heap[0].cancelled:
            heapq.heappop(heap)
        if not heap:
            return None
        return max(0.0, heap[0].when - self.clock())

    def run_due(self) -> None:
        now = self.clock()
        heap = self._heap
        while heap and heap[0].when <= now:
            timer = heapq.heappop(heap)
            if not timer.cancelled:
                timer.cancelled = True
                timer.callback()
