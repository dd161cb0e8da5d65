"""What the keys do in the ``--status`` view: select a process, look at its last lines.

rosmon's idea on mlaunch's table: one row is selected (up/down arrows, or j/k), and keys act on
it. ``l`` (or Enter) opens the pane of its last lines in place of the table, kept up to date
as the process prints; Esc or ``q`` goes back to the table. A help line of the keys sits at
the bottom of the view. The keys come from mlaunch.run.keyboard; the view (mlaunch.run.status)
draws what this module decides.

The last lines come from a bounded ring per process (``Recent``): the complete lines of its
output as the event stream carried them, at most ``RECENT_BYTES`` each, whatever the output
mode sends to the screen (a process whose output goes only to its log file shows here too).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

# Output kept per process for the pane; a whole chunk is dropped once the rest reaches it.
RECENT_BYTES = 64 * 1024

# The help lines (table, pane): the keys and what they do.
TABLE_HELP = "keys: \u2191\u2193 or j k select \u00b7 l last lines \u00b7 Ctrl-C stop all"
PANE_HELP = "keys: Esc or q back to the table \u00b7 \u2191\u2193 or j k other process"


class Recent:
    """The last ``limit`` bytes (or so) of each process's output, as complete lines."""

    def __init__(self, limit: int = RECENT_BYTES) -> None:
        self.limit = limit
        self._chunks: dict[str, deque[bytes]] = {}
        self._size: dict[str, int] = {}

    def add(self, label: str, data: bytes) -> None:
        """Complete lines (``data`` ends with a newline) of process ``label``."""
        if len(data) > self.limit:
            data = data[data.find(b"\n", len(data) - self.limit) + 1 :]
        chunks = self._chunks.get(label)
        if chunks is None:
            chunks = self._chunks[label] = deque()
            self._size[label] = 0
        chunks.append(data)
        size = self._size[label] + len(data)
        while size > self.limit and len(chunks) > 1:
            size -= len(chunks.popleft())
        self._size[label] = size

    def lines(self, label: str, count: int) -> list[bytes]:
        """The last ``count`` lines of ``label`` (fewer when it printed fewer), oldest first."""
        chunks = self._chunks.get(label)
        if not chunks or count <= 0:
            return []
        out: list[bytes] = []
        for chunk in reversed(chunks):
            out[:0] = chunk[:-1].split(b"\n")
            if len(out) >= count:
                break
        return out[-count:]


class StatusKeys:
    """The selection and the pane of one status view, moved by ``press(key)``.

    ``labels()`` gives the processes in the order the table lists them; ``changed()`` asks the
    view to draw again at once (a key is answered now, not at the next refresh).
    """

    def __init__(self, labels: Callable[[], list[str]], changed: Callable[[], None]) -> None:
        self.labels = labels
        self.changed = changed
        self.selected: str | None = None
        self.pane: str | None = None  # the process whose last lines are shown, if any
        self.recent = Recent()
        self._keys: dict[str, Callable[[], None]] = {
            "up": self.previous,
            "k": self.previous,
            "down": self.next,
            "j": self.next,
            "l": self.open_pane,
            "enter": self.open_pane,
            "esc": self.close_pane,
            "q": self.close_pane,
        }

    def press(self, key: str) -> None:
        """A key from the terminal; keys that mean nothing here are ignored."""
        action = self._keys.get(key)
        if action is not None:
            action()
            self.changed()

    def current(self) -> str | None:
        """The selected process: the first one until a key moves the selection."""
        labels = self.labels()
        if self.selected not in labels:
            self.selected = labels[0] if labels else None
        return self.selected

    def _move(self, step: int) -> None:
        labels = self.labels()
        if not labels:
            return
        current = self.current()
        index = labels.index(current) if current in labels else 0
        self.selected = labels[(index + step) % len(labels)]
        if self.pane is not None:
            self.pane = self.selected  # the pane follows the selection

    def previous(self) -> None:
        self._move(-1)

    def next(self) -> None:
        self._move(1)

    def open_pane(self) -> None:
        self.pane = self.current()

    def close_pane(self) -> None:
        self.pane = None

    def help_line(self) -> str:
        return PANE_HELP if self.pane is not None else TABLE_HELP

    def saw_output(self, label: str, data: bytes) -> None:
        self.recent.add(label, data)
