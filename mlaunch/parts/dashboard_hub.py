"""What the launch panel's two sides share: the part (mlaunch.parts.dashboard) writes the run's
state and output here from the loop and the metrics thread; the browsers' threads
(mlaunch.parts.dashboard_http) read it."""

from __future__ import annotations

import threading
from collections import deque

# Lines kept per process for the log view's follow (older ones are read from its log file).
RING = 2000
LINE_MAX = 2000  # characters of one output line sent to the page
# Browser streams served at once; more are refused (503) rather than given a thread each.
MAX_STREAMS = 64


class Hub:
    """What the browsers' threads read, written by the loop and the metrics thread.

    ``state`` is the latest message (JSON bytes) and ``version`` counts them; the state streams
    wait on ``changed``, which is notified once per message. ``lines`` keeps each label's last
    RING output lines numbered from ``first[label]``; the log views look at them a few times a
    second (``ended`` is set at the end), so a line of output wakes no thread.
    """

    def __init__(self) -> None:
        self.changed = threading.Condition()
        self.lock = threading.Lock()
        self.ended = threading.Event()
        self.version = 0
        self.state = b"{}"
        self.lines: dict[str, deque[str]] = {}
        self.first: dict[str, int] = {}  # the number of lines[label][0]
        self.last: dict[str, str] = {}
        self.history: dict[str, deque[tuple[float, int]]] = {}
        self.closed = False
        self.streams = 0
        self.looked = False  # a page has opened a stream: the readiness checks are worth watching

    def add_output(self, label: str, data: bytes) -> None:
        text = data.decode("utf-8", "replace").splitlines()
        if not text:
            return
        with self.lock:
            ring = self.lines.get(label)
            if ring is None:
                ring = self.lines[label] = deque(maxlen=RING)
                self.first[label] = 0
            # The ring keeps the last RING lines; the numbers of those it drops count on.
            if len(text) >= RING:
                self.first[label] += len(ring) + len(text) - RING
                ring.clear()
                text = text[-RING:]
            else:
                self.first[label] += max(0, len(ring) + len(text) - RING)
            ring.extend(line[:LINE_MAX] for line in text)
            self.last[label] = text[-1][:LINE_MAX]

    def end(self, label: str) -> int:
        """The number the label's next line will get (loop thread: no line arrives meanwhile)."""
        ring = self.lines.get(label)
        return self.first.get(label, 0) + (len(ring) if ring is not None else 0)

    def lines_since(self, label: str, number: int) -> tuple[int, list[str], int]:
        """(lines skipped, the lines from ``number`` on, the next number) for the log view."""
        with self.lock:
            ring = self.lines.get(label)
            if ring is None:
                return 0, [], number
            first = self.first[label]
            skipped = max(0, first - number)
            start = max(number, first) - first
            return skipped, list(ring)[start:], first + len(ring)

    def publish(self, state: bytes) -> None:
        with self.changed:
            self.state = state
            self.version += 1
            self.changed.notify_all()

    def close(self) -> None:
        with self.changed:
            self.closed = True
            self.changed.notify_all()
        self.ended.set()
