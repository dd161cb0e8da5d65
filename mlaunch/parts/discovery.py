"""How long a service client waits after it first sees its service, before its first request.

Seeing the service means this side has matched the server's endpoints; the server may not yet
have matched this client's response reader. Fast DDS then drops the answer after the server has
acted ("failed to send response (timeout): client will not receive response": the server waits
only 100 ms for the match), so the call never returns, and sending again would act twice (load a
component twice, run a lifecycle transition twice). It stalled about one test suite in two on an
idle 2-core machine. Waiting this long once per client costs little; a lost answer costs the
launch a component or a lifecycle step.
"""

from __future__ import annotations

import threading
import time

SETTLE = 0.5


class Settling:
    """When each client first saw its service; ``left(key)`` is the wait still owed before sending.

    A key whose service went away is ``forget``-ten, so a server that comes back (a new
    participant, the same race) is settled again.
    """

    def __init__(self) -> None:
        self._seen: dict[object, float] = {}
        self._lock = threading.Lock()

    def left(self, key: object) -> float:
        now = time.monotonic()
        with self._lock:
            seen = self._seen.setdefault(key, now)
        return max(0.0, seen + SETTLE - now)

    def forget(self, key: object) -> None:
        with self._lock:
            self._seen.pop(key, None)
