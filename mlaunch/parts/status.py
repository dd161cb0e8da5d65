"""Seeing what runs: the ``--status`` live view.

The live view (rosmon's idea, without taking over the screen) is a table pinned below the
scrolling output: one row per process with its state, pid, uptime, restarts, CPU and memory (of
its whole process group, sampled with psutil) and its last output line. It is redrawn about
twice a second from a supervisor timer, never from a thread, and it owns the screen while it is
shown: the Printer's screen output goes through it, so each burst of output is written above the
table by erasing the table, writing the lines and drawing the table again. Scrollback keeps
every output line and never a copy of the table. rich (to render the table) and psutil are
imported on the first refresh, after the first processes have started. Without ``--status``
nothing here is imported. In a terminal, keys select a process and act on it
(mlaunch.parts.status_keys, read by mlaunch.engine.keyboard). The exit summary is
mlaunch.parts.summary.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence

from mlaunch.engine.part import Part
from mlaunch.engine.process_state import (
    FAILED,
    GAVE_UP,
    RESTARTING,
    RUNNING,
    STOPPED,
    STOPPING,
    ProcessState,
)
from mlaunch.parts.summary import format_bytes, format_duration
from mlaunch.plan.records import Output, Record, Said

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Protocol

    from rich.console import Console

    from mlaunch.engine.guard import Guard
    from mlaunch.engine.keyboard import Keyboard
    from mlaunch.engine.part import AttachedRun
    from mlaunch.engine.process import Process
    from mlaunch.engine.process_state import ProcessState

    class ScreenOwner(Protocol):
        """What the status view uses of the printer (mlaunch.engine.output's Printer is one): the
        screen taken and given back, whether a label is muted, whether it writes in colour."""

        @property
        def color(self) -> bool: ...

        def set_screen(self, out: Callable[[bytes], object]) -> Callable[[bytes], object]: ...

        def is_muted(self, label: str) -> bool: ...

    class ViewedRun(AttachedRun, Protocol):
        """What the status view uses of the run (the Supervisor is one): what it knows of each
        label, its processes, the guard (which puts the terminal back after kill -9)."""

        @property
        def process_states(self) -> Mapping[str, ProcessState]: ...

        @property
        def processes(self) -> list[Process]: ...

        @property
        def guard(self) -> Guard | None: ...

    from mlaunch.parts.control import Control
    from mlaunch.parts.status_keys import StatusKeys
    from mlaunch.parts.usage import GroupSampler

REFRESH = 0.5
# The table takes at most this share of the terminal's height; output scrolls above it.
MAX_SHARE = 0.5
LAST_LINE = 300

STATE_STYLE = {
    RUNNING: "green",
    STOPPING: "yellow",
    RESTARTING: "yellow",
    FAILED: "bold red",
    GAVE_UP: "bold red",
    STOPPED: "blue",  # by the user: neither a failure nor the end
}
# The table's columns, and which go first when the terminal is too narrow for all of them.
COLUMNS = (
    ("process", "left"), ("state", "left"), ("pid", "right"), ("uptime", "right"),
    ("restarts", "right"), ("cpu", "right"), ("memory", "right"), ("last output", "left"),
)  # fmt: skip
DROP_ORDER = (7, 6, 5, 3, 4, 2)
LAST_OUTPUT_MIN = 12  # narrower, the last output says nothing: the column goes
COLUMN_GAP = 2
# Which rows to keep when there are more processes than room: trouble first.
STATE_ORDER = {FAILED: 0, GAVE_UP: 0, RESTARTING: 1, STOPPING: 2, STOPPED: 2, RUNNING: 3}


# --- the live view --------------------------------------------------------------------------------


def terminal_size(fd: int = 1) -> tuple[int, int]:
    """(columns, lines) of the terminal; 80x24 when it reports 0x0 (some pseudo-terminals
    and serial consoles do), so the table never draws into nothing."""
    try:
        size = os.get_terminal_size(fd)
    except OSError:
        return 100, 30
    return size.columns or 80, size.lines or 24


class StatusView(Part):
    """The live table. Seams: ``size`` (columns, lines), ``color``, ``period``, ``sampler``.

    ``sampler(pids_by_group) -> {pgid: (cpu_percent, rss)}``; the default uses psutil.
    """

    def __init__(
        self,
        supervisor: ViewedRun,
        printer: ScreenOwner,
        control: Callable[[], Control],
        *,
        size: Callable[[], tuple[int, int]] = terminal_size,
        color: bool = True,
        period: float = REFRESH,
        sampler: Callable[[dict[int, list[int]]], dict[int, tuple[float, int]]] | None = None,
        wall_clock: Callable[[], float] = time.time,
    ) -> None:
        self.supervisor = supervisor
        self.printer = printer
        self.control = control  # the run's runtime control, made when a key first needs it
        self.size = size
        self.color = color
        self.period = period
        self.sampler = sampler
        self.wall_clock = wall_clock
        self.last_line: dict[str, bytes] = {}
        self.usage: dict[int, tuple[float, int]] = {}
        self.frames = 0
        self._pending: list[bytes] = []
        self._pending_size = 0
        self._footer = b""
        self._drawn = 0  # lines of the table now on screen (the cursor is at its last line's end)
        self._redraw = False
        self._urgent = False
        self._closed = False
        self._usage: GroupSampler | None = None  # psutil, on the first refresh
        # Keys (mlaunch.parts.status_keys), when the terminal can type them: ``enable_keys``.
        self.keys: StatusKeys | None = None
        self.keyboard: Keyboard | None = None
        self.screen = self.printer.set_screen(self)
        supervisor.records.subscribe(self._saw_output)
        supervisor.schedule(0.0, self._tick, keeps_alive=False, cancel_on_shutdown=False)

    # --- the screen, as the Printer sees it ----------------------------------------------------

    def __call__(self, data: bytes) -> None:
        self._pending.append(data)
        self._pending_size += len(data)
        if self._pending_size >= 256 * 1024:
            self.flush()

    def urgent(self, data: bytes) -> None:
        """mlaunch's own messages: the frame that carries them must not be dropped."""
        self._urgent = True
        self(data)

    @property
    def blocked(self) -> bool:
        return bool(getattr(self.screen, "blocked", False))

    def flush(self) -> None:
        """Output above the table, then the table again: one write, so nothing flickers."""
        if self._pending or self._redraw:
            frame = self._erase() + b"".join(self._pending) + self._footer
            self._drawn = self._footer.count(b"\n") + 1 if self._footer else 0
            self._pending.clear()
            self._pending_size = 0
            self._redraw = False
            self.frames += 1
            write = getattr(self.screen, "urgent", self.screen) if self._urgent else self.screen
            self._urgent = False
            write(frame)
        flush = getattr(self.screen, "flush", None)
        if flush is not None:
            flush()

    def _erase(self) -> bytes:
        if not self._drawn:
            return b""
        up = b"\x1b[%dA" % (self._drawn - 1) if self._drawn > 1 else b""
        return b"\r" + up + b"\x1b[J"

    def close(self) -> None:
        """Take the table off the screen and give the screen back to the Printer."""
        if self._closed:
            return
        self._closed = True
        if self.keyboard is not None:
            self.keyboard.close()  # the terminal's own mode back before anything else
        self._footer = b""
        self._redraw = True
        self.flush()
        self.printer.set_screen(self.screen)
        self.supervisor.records.unsubscribe(self._saw_output)

    # --- what it shows --------------------------------------------------------------------------

    def enable_keys(self) -> StatusKeys:
        """Select a process with the keys and act on it (``press`` them on ``keys``); the
        table gets a marked row and a help line."""
        from mlaunch.parts.status_keys import StatusKeys

        supervisor = self.supervisor
        self.keys = StatusKeys(
            lambda: list(supervisor.process_states),
            self.redraw,
            self.control,
            supervisor.clock,
        )
        return self.keys

    def read_keys(self, fd: int) -> Keyboard:
        """Take keys from the terminal ``fd``: cbreak mode until ``close`` (run/keyboard.py)."""
        from mlaunch.engine.keyboard import Keyboard

        keys = self.keys or self.enable_keys()
        guard = self.supervisor.guard
        self.keyboard = Keyboard(
            self.supervisor.selector,
            keys.press,
            fd=fd,
            tell_guard=guard.terminal if guard is not None else None,
        )
        self.keyboard.start()
        return self.keyboard

    def redraw(self) -> None:
        """Draw the view again now, with the usage last sampled (a key was pressed)."""
        if not self._closed:
            self._footer = self.render().encode("utf-8", "replace")
            self._redraw = True

    def _saw_output(self, record: Record) -> None:
        if not isinstance(record, Output):
            return
        data = record.data
        end = len(data) - 1  # data is complete lines: it ends with a newline
        start = data.rfind(b"\n", 0, end) + 1
        self.last_line[record.process.label] = data[start : min(end, start + LAST_LINE)]

    def _tick(self) -> None:
        if self._closed:
            return
        if self.keyboard is not None:
            self.keyboard.check()  # job control: back in the foreground after Ctrl-Z, fg
        self.usage = self._sample()
        self._footer = self.render().encode("utf-8", "replace")
        self._redraw = True
        self.supervisor.schedule(
            self.period, self._tick, keeps_alive=False, cancel_on_shutdown=False
        )

    def _groups(self) -> dict[int, list[int]]:
        """Living members of each running process's group (one /proc scan for all)."""
        from mlaunch.parts.usage import group_members

        return group_members({p.pid for p in self.supervisor.processes if p.running})

    def _sample(self) -> dict[int, tuple[float, int]]:
        groups = self._groups()
        if self.sampler is not None:
            return self.sampler(groups)
        if self._usage is None:
            from mlaunch.parts.usage import GroupSampler

            self._usage = GroupSampler(details=False)
        return {pgid: (u.cpu, u.rss) for pgid, u in self._usage.sample(groups).items()}

    def rows(self) -> list[tuple[ProcessState, str, str, str, str, str, str]]:
        """(record, state, pid, uptime, cpu, memory, last line) for each process, as text."""
        now = self.supervisor.clock()
        out = []
        for record in self.supervisor.process_states.values():
            running = record.state in (RUNNING, STOPPING)
            cpu, rss = self.usage.get(record.pid, (0.0, 0)) if running else (0.0, 0)
            if running:
                uptime = format_duration(max(0.0, now - record.started_at))
            elif record.state == RESTARTING and record.restart_at is not None:
                uptime = f"restart in {max(0.0, record.restart_at - now):.1f} s"
            else:
                uptime = "-"
            out.append(
                (
                    record,
                    record.state,
                    str(record.pid or "-") if running else "-",
                    uptime,
                    f"{cpu:.0f}%" if running else "-",
                    format_bytes(rss) if running else "-",
                    _printable(self.last_line.get(record.label, b"")),
                )
            )
        return out

    def render(self) -> str:
        """The view as terminal text (ANSI styles when ``color``), no trailing newline: the
        table (or the pane of a process's last lines), then the keys' help line if any."""
        import io

        from rich.console import Console
        from rich.text import Text

        columns, lines = self.size()
        out = io.StringIO()
        console = Console(
            file=out,
            width=max(40, columns - 1),
            force_terminal=True,
            color_system="standard" if self.color else None,
            no_color=not self.color,
            highlight=False,
            legacy_windows=False,
        )
        keys = self.keys
        if keys is not None and keys.pane is not None:
            self._print_pane(console, keys.pane, lines)
        else:
            self._print_table(console, lines)
        if keys is not None and (self.keyboard is None or self.keyboard.reading):
            # (Not while mlaunch is in the background: the keys do not reach it there.)
            line = keys.help_line()
            style = "yellow" if keys.notice else "dim"
            console.print(Text(line, style=style, no_wrap=True, overflow="ellipsis"))
        return out.getvalue().rstrip("\n")

    def _print_table(self, console: Console, lines: int) -> None:
        from rich import box
        from rich.table import Table
        from rich.text import Text

        rows = self.rows()
        selected = self.keys.current() if self.keys is not None else None
        room = max(1, int(lines * MAX_SHARE) - (5 if self.keys is not None else 4))
        hidden = 0
        if len(rows) > room:
            # Trouble first, and the selected row always.
            keep = sorted(
                range(len(rows)),
                key=lambda i: (rows[i][0].label != selected, STATE_ORDER.get(rows[i][1], 4), i),
            )
            kept = set(keep[:room])
            hidden = len(rows) - room
            rows = [row for i, row in enumerate(rows) if i in kept]
        counts: dict[str, int] = {}
        for record in self.supervisor.process_states.values():
            counts[record.state] = counts.get(record.state, 0) + 1
        title = "mlaunch: " + ", ".join(f"{n} {state}" for state, n in counts.items())
        if hidden:
            title += f" ({hidden} not shown)"
        table = Table(
            title=Text(title, style="bold"),
            title_justify="left",
            box=box.SIMPLE_HEAD,
            pad_edge=False,
            show_edge=False,
            expand=True,
            padding=(0, 1),
            collapse_padding=True,
        )
        cells, styles = self._cells(rows, selected)
        shown = fitting_columns(cells, console.width)
        for i in shown:
            name, justify = COLUMNS[i]
            if name == "last output":
                table.add_column(name, no_wrap=True, overflow="ellipsis", ratio=1)
            else:
                table.add_column(name, justify=justify, no_wrap=True)  # type: ignore[arg-type]
        for row, (label_style, state_style) in zip(cells, styles, strict=True):
            # The label cell alone is highlighted: a reversed row shows gaps at column breaks.
            row_styles = {0: label_style, 1: state_style, 7: "dim"}
            table.add_row(*(Text(row[i], style=row_styles.get(i, "")) for i in shown))
        console.print(table)

    def _cells(
        self, rows: list[tuple[ProcessState, str, str, str, str, str, str]], selected: str | None
    ) -> tuple[list[tuple[str, ...]], list[tuple[str, str]]]:
        """Each row's cells as text (COLUMNS), and the styles of its label and state."""
        cells: list[tuple[str, ...]] = []
        styles: list[tuple[str, str]] = []
        for record, state, pid, uptime, cpu, rss, last in rows:
            label = record.label
            if self.keys is not None:
                # A marker as well as the highlight: without colours it is all there is.
                label = ("> " if label == selected else "  ") + label
            text = self._state_text(record)
            cells.append((label, text, pid, uptime, str(record.restarts), cpu, rss, last))
            styles.append(
                ("reverse" if record.label == selected else "", STATE_STYLE.get(state, "dim"))
            )
        return cells, styles

    def _print_pane(self, console: Console, label: str, lines: int) -> None:
        """The last lines ``label`` printed, as many as the table's share of the screen."""
        from rich.text import Text

        assert self.keys is not None
        record = self.supervisor.process_states.get(label)
        state = self._state_text(record) if record is not None else "-"
        shown, problem = self.keys.last_lines(label, max(1, int(lines * MAX_SHARE) - 2))
        what = f"its last {len(shown)} lines" if shown else problem or "no output yet"
        console.print(Text(f"{label}: {state}, {what}", style="bold", no_wrap=True))
        for line in shown:
            text = _printable(line.encode(), strip=False)
            console.print(Text(text, no_wrap=True, overflow="ellipsis"))

    def _state_text(self, record: ProcessState) -> str:
        """The state as the table shows it: whether the user stopped or muted it too."""
        state = record.outcome if record.state == STOPPED else record.state
        if self.printer.is_muted(record.label):
            state += ", muted"
        return state


def fitting_columns(cells: Sequence[Sequence[str]], width: int) -> list[int]:
    """Which of COLUMNS fit ``width`` whole: on a narrow terminal the least needed go first
    (last output, then memory, cpu, uptime, restarts, pid) rather than every number being cut.
    Process and state always stay (a long label is cut instead)."""
    widths = [
        max([len(name), *(len(row[i]) for row in cells)]) for i, (name, _) in enumerate(COLUMNS)
    ]
    widths[-1] = LAST_OUTPUT_MIN
    shown = list(range(len(COLUMNS)))
    for i in DROP_ORDER:
        if sum(widths[j] for j in shown) + COLUMN_GAP * (len(shown) - 1) <= width:
            break
        shown.remove(i)
    return shown


def _printable(raw: bytes, *, strip: bool = True) -> str:
    """A child's line without its colours and control characters (they would break rows)."""
    text = raw.decode("utf-8", "replace")
    if "\x1b" in text:
        from rich.text import Text

        text = Text.from_ansi(text).plain
    text = "".join(ch if ch.isprintable() else " " for ch in text)
    return text.strip() if strip else text.rstrip()


def attach_status_view(
    supervisor: ViewedRun, printer: ScreenOwner, control: Callable[[], Control]
) -> StatusView | None:
    """The view on a terminal; on anything else a warning (redrawing would fill a log file).

    With a terminal on stdin too, its keys select a process and act on it (``read_keys``).
    """
    if not os.isatty(1):
        text = "--status needs a terminal on stdout; no status view"
        supervisor.records.emit(Said("WARNING", "launch", text))
        return None
    view = StatusView(supervisor, printer, control, color=printer.color)
    if os.isatty(0):
        view.read_keys(0)
    return view
