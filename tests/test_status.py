"""The --status live view and the exit summary.

The live view is checked the way a terminal sees it: the bytes it writes are fed to a tiny
terminal model (cursor up, erase down, carriage return, newline) to see what stays in the
scrollback and what is on the last lines.
"""

from __future__ import annotations

import re
import signal
import time
from pathlib import Path

from test_supervision import Harness, make_spec

from mlaunch.engine.process_state import FAILED, FINISHED, GAVE_UP, RUNNING, ProcessState
from mlaunch.parts.status import StatusView, attach_status_view
from mlaunch.parts.summary import (
    ExitSummary,
    format_bytes,
    format_duration,
    render_summary,
    summary_wanted,
)
from mlaunch.plan.steps import ProcessSpec, RespawnPolicy

CSI = re.compile(r"\x1b\[(\d*)([A-Za-z])")


class Terminal:
    """Just enough of a terminal for the view: text, \\r, \\n, ESC[nA, ESC[J, colours ignored."""

    def __init__(self) -> None:
        self.lines = [""]
        self.row = 0
        self.col = 0

    def feed(self, data: bytes) -> None:
        text = data.decode("utf-8")
        i = 0
        while i < len(text):
            match = CSI.match(text, i)
            if match:
                n = int(match.group(1) or 1)
                if match.group(2) == "A":
                    self.row = max(0, self.row - n)
                elif match.group(2) == "J":
                    self.lines[self.row] = self.lines[self.row][: self.col]
                    del self.lines[self.row + 1 :]
                i = match.end()
                continue
            ch = text[i]
            if ch == "\r":
                self.col = 0
            elif ch == "\n":
                self.row += 1
                self.col = 0
                if self.row == len(self.lines):
                    self.lines.append("")
            else:
                line = self.lines[self.row].ljust(self.col)
                self.lines[self.row] = line[: self.col] + ch + line[self.col + 1 :]
                self.col += 1
            i += 1

    def text_lines(self) -> list[str]:
        return [line.rstrip() for line in self.lines if line.strip()]


def record(label: str, state: str, **kw: object) -> ProcessState:
    spec = ProcessSpec(label=label, argv=("x",), env={}, env_changes={})
    rec = ProcessState(label, spec, state=state)
    for key, value in kw.items():
        setattr(rec, key, value)
    return rec


# --- formatting ----------------------------------------------------------------------------------


def test_formatting() -> None:
    assert format_duration(0.25) == "0.25 s"
    assert format_duration(42.0) == "42.0 s"
    assert format_duration(723) == "12:03"
    assert format_duration(3723) == "1:02:03"
    assert format_bytes(0) == "-"
    assert format_bytes(812 * 1024) == "812 KiB"
    assert format_bytes(35.2 * (1 << 20)) == "35.2 MiB"
    assert format_bytes(1.5 * (1 << 30)) == "1.5 GiB"


# --- the exit summary ----------------------------------------------------------------------------


def test_when_the_summary_is_printed() -> None:
    clean = record("a-1", FINISHED, outcome="finished cleanly")
    other = record("b-2", FINISHED, outcome="stopped by SIGINT")
    bad = record("c-3", FAILED, outcome="exited with status 1", failed=True)
    gave_up = record("d-4", GAVE_UP, outcome="gave up after 3 restarts: exited with status 0")
    assert not summary_wanted([clean])  # one process that ended well: quiet
    assert summary_wanted([clean, other])  # more than one process
    assert summary_wanted([bad])  # any failure
    assert summary_wanted([gave_up])
    assert not summary_wanted([clean, other], quiet=True)  # --quiet: only failures
    assert summary_wanted([clean, bad], quiet=True)


def test_summary_table() -> None:
    rows = [
        record("talker-1", FINISHED, pid=101, outcome="stopped by SIGINT", run_time=723.0,
               peak_rss=35 << 20, cpu_time=1.5),
        record("crasher-2", GAVE_UP, pid=2202, restarts=3, failed=True, run_time=0.2,
               outcome="gave up after 3 restarts: killed by SIGSEGV (core dumped)"),
    ]  # fmt: skip
    text = render_summary(rows)
    lines = text.splitlines()
    assert lines[0] == "Summary: 2 processes, 1 failed"
    assert lines[1].split() == [
        "process", "pid", "result", "restarts", "run", "time", "peak", "memory", "cpu", "time"
    ]  # fmt: skip
    assert re.match(r"  talker-1 +101 +stopped by SIGINT +0 +12:03 +35\.0 MiB +1\.50 s$", lines[2])
    assert "killed by SIGSEGV (core dumped)" in lines[3] and " 3 " in lines[3]
    # Columns line up: every row is as wide as the header.
    assert len({len(line) for line in lines[1:]}) <= 2


def test_exit_summary_after_a_run_reports_each_process() -> None:
    h = Harness(
        [
            make_spec("ok", "print('fine')"),
            make_spec("bad", "import sys; sys.exit(3)"),
        ]
    )
    assert h.run() == 0
    ExitSummary(h.sup.process_states, h.sup.records.emit).close()
    text = h.text
    assert "Summary: 2 processes, 1 failed" in text
    ok_row = next(line for line in text.splitlines() if line.startswith("  ok "))
    bad_row = next(line for line in text.splitlines() if line.startswith("  bad "))
    assert "finished cleanly" in ok_row and "MiB" in ok_row  # peak memory from wait4
    assert "exited with status 3" in bad_row


def test_one_clean_process_prints_no_summary() -> None:
    h = Harness([make_spec("only", "pass")])
    assert h.run() == 0
    ExitSummary(h.sup.process_states, h.sup.records.emit).close()
    assert "Summary" not in h.text


# --- the live view -------------------------------------------------------------------------------


def fake_usage(groups: dict[int, list[int]]) -> dict[int, tuple[float, int]]:
    return {pgid: (12.0, 3 << 20) for pgid in groups}


def test_status_view_keeps_the_scrollback_clean(tmp_path: Path) -> None:
    # The talker lives on after its ticks until the view has drawn six frames (60 s at most):
    # 0.6 s held fewer on a loaded machine.
    drawn = tmp_path / "drawn"
    code = f"""
    import os, time
    for i in range(5):
        print("tick", i, flush=True)
        time.sleep(0.12)
    deadline = time.monotonic() + 60
    while not os.path.exists({str(drawn)!r}) and time.monotonic() < deadline:
        time.sleep(0.02)  # the child under test, not a test: polling is fine
    """
    policy = RespawnPolicy(mode="on-failure", delay=0.2, max_retries=1)
    h = Harness(
        [
            make_spec("talker", code),
            make_spec("crasher", "import sys; sys.exit(2)", respawn=policy),
        ]
    )
    view = StatusView(
        h.sup,
        h.printer,
        h.control,
        size=lambda: (110, 40),
        color=False,
        period=0.05,
        sampler=fake_usage,
    )

    def watch() -> None:
        if view.frames > 5:
            drawn.touch()
        else:
            h.sup.schedule(0.05, watch, keeps_alive=False)

    watch()
    assert h.run() == 0
    assert view.frames > 5  # redrawn while it ran, not just once
    term = Terminal()
    term.feed(bytes(h.screen))
    shown = term.text_lines()
    # While the run is on, the table sits on the last lines, below the output.
    table_top = max(i for i, line in enumerate(shown) if line.startswith("mlaunch: "))
    assert shown[table_top].startswith("mlaunch: ")
    assert any(line.startswith("talker ") for line in shown[table_top:])
    assert not any("tick 4" in line for line in shown[table_top:-2])
    view.close()
    term = Terminal()
    term.feed(bytes(h.screen))
    final = term.text_lines()
    # After close: only the output and launch's messages, each once, in order; no table.
    assert not any(line.startswith("mlaunch: ") for line in final)
    assert not any("process " in line and "state" in line for line in final)
    ticks = [line for line in final if line.startswith("[talker] tick")]
    assert ticks == [f"[talker] tick {i}" for i in range(5)]
    assert sum("giving up after 1 restarts" in line for line in final) == 1
    assert h.printer.screen is not view  # the printer has its screen back


def test_status_rows_show_state_usage_and_the_last_line_without_colours() -> None:
    h = Harness([make_spec("talker", "print('\\x1b[32mgreen hello\\x1b[0m')\nprint('bye')")])
    view = StatusView(
        h.sup, h.printer, h.control, size=lambda: (120, 40), color=False, sampler=fake_usage
    )
    running: list[str] = []

    def snapshot(what: str, process: object) -> None:
        if what == "started":
            view.usage = fake_usage({h.sup.states["talker"].pid: []})
            running.append(view.render())

    h.listen(snapshot)
    assert h.run() == 0
    row = next(line for line in running[0].splitlines() if line.startswith("talker"))
    pid = str(h.sup.states["talker"].pid)
    assert re.search(rf"talker +running +{pid} +\d+\.\d\d s +0 +12% +3\.0 MiB", row), row
    final = view.render()
    assert "bye" in final and "\x1b" not in final  # colour codes of a child never reach the table
    ended = next(line for line in final.splitlines() if line.startswith("talker"))
    assert "finished" in ended
    view.close()


def test_status_view_keeps_failing_rows_when_there_is_no_room() -> None:
    h = Harness([])
    view = StatusView(
        h.sup, h.printer, h.control, size=lambda: (100, 16), color=False, sampler=fake_usage
    )
    for i in range(20):
        h.sup.states[f"n{i}-{i}"] = record(f"n{i}-{i}", RUNNING, pid=1000 + i)
    h.sup.states["bad-99"] = record("bad-99", FAILED, failed=True)
    text = view.render()
    assert "bad-99" in text and "not shown" in text
    assert len(text.splitlines()) <= 16
    view.close()


def test_status_view_samples_real_processes_with_psutil() -> None:
    h = Harness([make_spec("worker", "import time; print('up', flush=True); time.sleep(30)")])
    view = StatusView(h.sup, h.printer, h.control, size=lambda: (120, 40), color=False)
    usage: list[dict[int, tuple[float, int]]] = []

    def sample_then_stop(label: str, line: bytes) -> None:
        usage.append(view._sample())
        h.shutdown()

    h.when(b"up", sample_then_stop)
    assert h.run() == 0
    pid = h.sup.states["worker"].pid
    assert usage[0][pid][1] > 1 << 20  # a Python child's resident memory
    view.close()


def test_status_view_needs_a_terminal(tmp_path: object) -> None:
    h = Harness([])
    import os

    r, w = os.pipe()
    saved = os.dup(1)
    try:
        os.dup2(w, 1)  # stdout is a pipe here, as under CI
        assert attach_status_view(h.sup, h.printer, h.control) is None
    finally:
        os.dup2(saved, 1)
        for fd in (r, w, saved):
            os.close(fd)
    assert "--status needs a terminal" in h.text


def test_status_refresh_never_keeps_an_idle_launch_alive() -> None:
    h = Harness([make_spec("quick", "pass")])
    StatusView(
        h.sup,
        h.printer,
        h.control,
        size=lambda: (80, 24),
        color=False,
        period=0.05,
        sampler=fake_usage,
    )
    started = time.monotonic()
    assert h.run() == 0
    assert time.monotonic() - started < 5
    assert signal.getsignal(signal.SIGCHLD) == signal.SIG_DFL
