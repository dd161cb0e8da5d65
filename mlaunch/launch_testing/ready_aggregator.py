"""``launch_testing.ReadyAggregator``: one ready signal out of several."""

from __future__ import annotations

import threading

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable


class ReadyAggregator:
    """Calls ``ready_fn`` once ``ReadyAggregator.ready_fn`` was called ``num_to_aggregate`` times
    (from any thread); later calls do nothing."""

    def __init__(self, ready_fn: Callable[[], object], num_to_aggregate: int) -> None:
        self._parent_ready_fn = ready_fn
        self._count_to_activate = num_to_aggregate
        self._lock = threading.Lock()

    def ready_fn(self) -> None:
        with self._lock:
            self._count_to_activate -= 1
            now_ready = self._count_to_activate == 0
        # Called outside the lock: it may well call back into code that takes it.
        if now_ready:
            self._parent_ready_fn()


__all__ = ["ReadyAggregator"]
