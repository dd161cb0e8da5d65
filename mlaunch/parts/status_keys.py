"""What the keys do in the ``--status`` view: select a process and act on it, as in rosmon.

One row is selected (up/down arrows, or j/k) and the keys act on it through the run's control
core (mlaunch.parts.control, the same operations as ``mlaunch ctl``): ``s`` start, ``x`` stop,
``r`` restart, ``m`` mute, ``u`` unmute. ``l`` (or Enter) shows its log: its last lines (control's
``logs``: from its log file, so a process whose output goes only there shows too) in place of
the table, kept up to date; Esc or ``q`` goes back. A help line of the keys sits at the bottom
of the view; a request that cannot be carried out (starting a running process, acting while
the launch shuts down) shows why there instead, for a few seconds. The keys come from
mlaunch.engine.keyboard; the view (mlaunch.parts.status) draws what this module decides.
"""

from __future__ import annotations

from collections.abc import Callable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.parts.control import Control

# The help lines (table, pane): the keys and what they do, within 80 columns.
ACTIONS_HELP = "s start  x stop  r restart  m mute  u unmute"
TABLE_HELP = f"\u2191\u2193/jk select  {ACTIONS_HELP}  l log  Ctrl-C quit"
PANE_HELP = f"Esc/q back  \u2191\u2193/jk other process  {ACTIONS_HELP}"
# How long a request's problem stays in place of the help line (unless another key is pressed).
NOTICE_SECONDS = 5.0


class StatusKeys:
    """The selection, the pane and the key bindings of one status view: ``press(key)``.

    ``labels()`` gives the processes in the order the table lists them; ``changed()`` asks the
    view to draw again at once (a key is answered now, not at the next refresh); ``control()``
    gives the run's control core (made on the first key that needs it); ``clock`` times notices.
    """

    def __init__(
        self,
        labels: Callable[[], list[str]],
        changed: Callable[[], None],
        control: Callable[[], Control],
        clock: Callable[[], float],
    ) -> None:
        self.labels = labels
        self.changed = changed
        self.control = control
        self.clock = clock
        self.selected: str | None = None
        self.pane: str | None = None  # the process whose last lines are shown, if any
        self.notice = ""  # why the last request was not carried out
        self._notice_until = 0.0
        self._keys: dict[str, Callable[[], None]] = {
            "up": self.previous,
            "k": self.previous,
            "down": self.next,
            "j": self.next,
            "l": self.open_pane,
            "enter": self.open_pane,
            "esc": self.close_pane,
            "q": self.close_pane,
            "s": lambda: self._act(lambda c, label: c.start(label, by="keys")),
            "x": lambda: self._act(lambda c, label: c.stop(label, by="keys")),
            "r": lambda: self._act(lambda c, label: c.restart(label, by="keys")),
            "m": lambda: self._act(lambda c, label: c.mute(label, by="keys")),
            "u": lambda: self._act(lambda c, label: c.unmute(label, by="keys")),
        }

    def press(self, key: str) -> None:
        """A key from the terminal; keys that mean nothing here are ignored."""
        action = self._keys.get(key)
        if action is not None:
            self.notice = ""
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

    def _act(self, request: Callable[[Control, str], object]) -> None:
        """Carry out a request on the selected process; if it cannot be, say why for a while."""
        from mlaunch.parts.control import ControlError

        label = self.current()
        if label is None:
            return
        try:
            request(self.control(), label)
        except ControlError as e:
            self.notice = str(e)
            self._notice_until = self.clock() + NOTICE_SECONDS

    def last_lines(self, label: str, count: int) -> tuple[list[str], str]:
        """(the last ``count`` lines of ``label``'s output, why there are none if so)."""
        from mlaunch.parts.control import ControlError

        try:
            return self.control().logs(label, count), ""
        except ControlError as e:
            return [], str(e)

    def help_line(self) -> str:
        """The keys, or why the last request was not carried out (for a few seconds)."""
        if self.notice and self.clock() < self._notice_until:
            return self.notice
        self.notice = ""
        return PANE_HELP if self.pane is not None else TABLE_HELP
