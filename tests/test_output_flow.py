"""Output flow control: a reader that keeps up gets every line, a slow one slows the children
down instead of losing lines, a stalled one costs screen lines only after the stall time (said
so), and memory stays bounded. Plus the cheap per-run costs: batched guard writes and the stray
sweep that walks the process tree instead of scanning /proc.

The screen is a real pipe (mlaunch's Screen writing to it non-blocking); a thread in the test is
the reader, fast, slow or stopped. Waits are deadline loops, never bare sleeps as sync.
"""

from __future__ import annotations

import os
import re
import selectors
import shutil
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest
from procutil import wait_until
from test_supervision import Harness, gone, make_spec

from mlaunch.engine import guard as guards
from mlaunch.engine import proctable
from mlaunch.engine.output import Printer
from mlaunch.engine.screen import Screen
from mlaunch.engine.strays import Strays
from mlaunch.engine.supervisor import Supervisor
from mlaunch.plan.records import Output, Record
from mlaunch.plan.steps import Plan, Spawn

PY = sys.executable
DROP = re.compile(rb"the terminal fell behind: (\d+) lines")


def flood_code(n: int, tag: str, stamp: Path | None = None) -> str:
    """A child printing ``<tag> <i>`` for i < n in big writes; ``stamp`` gets its start/end."""
    code = f"""
    import sys, time
    t0 = time.monotonic()
    w = sys.stdout.buffer.write
    for s in range(0, {n}, 10_000):
        w(b"".join(b"{tag} %d\\n" % i for i in range(s, min(s + 10_000, {n}))))
    sys.stdout.flush()
    """
    if stamp is not None:
        code += f"""
    open({str(stamp)!r}, "w").write(f"{{t0}} {{time.monotonic()}}")
    """
    return code


class Reader(threading.Thread):
    """Reads a pipe into memory. ``pause_for``: read nothing for that long after the first
    byte; ``chunk``/``every``: a slow but steady reader (``chunk`` bytes per ``every`` s)."""

    def __init__(
        self, fd: int, *, pause_for: float = 0.0, chunk: int = 1 << 20, every: float = 0.0
    ) -> None:
        super().__init__(daemon=True)
        self.fd = fd
        self.pause_for = pause_for
        self.chunk = chunk
        self.every = every
        self.data = bytearray()
        self.paused_until = 0.0
        self.stop_at: float | None = None  # stop once nothing came for a while after this

    def run(self) -> None:
        sel = selectors.DefaultSelector()
        sel.register(self.fd, selectors.EVENT_READ)
        quiet_since = time.monotonic()
        while True:
            if not sel.select(0.05):
                if self.stop_at is not None and time.monotonic() - quiet_since > 0.3:
                    return
                continue
            try:
                got = os.read(self.fd, self.chunk)
            except OSError:
                return
            if not got:
                return
            quiet_since = time.monotonic()
            self.data += got
            if self.pause_for and not self.paused_until:
                # The terminal is paused (Ctrl-S): nothing is taken for a while.
                self.paused_until = time.monotonic() + self.pause_for
                deadline_sleep(self.paused_until)
            elif self.every:
                deadline_sleep(time.monotonic() + self.every)


def deadline_sleep(until: float) -> None:
    """The reader's own pacing (it is the slow terminal, not a synchronisation)."""
    while (left := until - time.monotonic()) > 0:
        time.sleep(min(left, 0.05))


def run_with_reader(
    specs: list, reader_kw: dict, screen_kw: dict, **harness_kw: object
) -> tuple[Harness, Screen, Reader]:
    r, w = os.pipe()
    screen = Screen(w, **screen_kw)
    reader = Reader(r, **reader_kw)
    reader.start()
    h = Harness(specs, out=screen, **harness_kw)  # type: ignore[arg-type]
    try:
        assert h.run(timeout=40) == 0
        screen.close(timeout=20)
        assert not screen.blocked, "the reader never took the rest"
    finally:
        os.close(w)
        reader.stop_at = time.monotonic()
        reader.join(30)
        os.close(r)
    assert not reader.is_alive()
    return h, screen, reader


def child_lines(data: bytes, label: str, tag: str) -> list[int]:
    prefix = f"[{label}] {tag} ".encode()
    return [int(line[len(prefix) :]) for line in data.split(b"\n") if line.startswith(prefix)]


# --- the screen -----------------------------------------------------------------------------------


@pytest.mark.serial  # the reader keeps up only with a core to itself
def test_a_reader_that_keeps_up_gets_every_line(tmp_path: Path) -> None:
    n = 250_000
    specs = [make_spec(f"f{i}", flood_code(n, "line")) for i in range(4)]
    h, screen, reader = run_with_reader(specs, {}, {}, log_dir=str(tmp_path))
    data = bytes(reader.data)
    assert b"fell behind" not in data
    assert screen.dropped_lines == 0
    for i in range(4):
        assert child_lines(data, f"f{i}", "line") == list(range(n)), f"f{i} lost or reordered"
        assert (tmp_path / f"f{i}.log").read_bytes().count(b"\n") == n
    assert b"process has finished cleanly" in data
    assert screen.peak <= screen.limit
    print(f"4 x {n} lines through a pipe: {4 * n / h.elapsed:,.0f} lines/s, peak {screen.peak}")


def test_a_slow_reader_slows_the_children_down_and_loses_nothing(tmp_path: Path) -> None:
    # ~3 MB/s at most (32 KiB every 10 ms) for ~4.6 MB of output.
    n = 200_000
    stamp = tmp_path / "stamp"
    specs = [make_spec("slowed", flood_code(n, "s", stamp))]
    # A slow but steady reader: the stall rule (1 s without progress, tested below) is put far
    # off, since this reader is a thread the loaded machine may not run for a second (a fresh
    # clone's CI, 4 workers on 2 cores: it fell behind once).
    _, screen, reader = run_with_reader(specs, {"chunk": 32 * 1024, "every": 0.01}, {"stall": 30.0})
    data = bytes(reader.data)
    assert b"fell behind" not in data and screen.dropped_lines == 0
    assert child_lines(data, "slowed", "s") == list(range(n))
    started, ended = map(float, stamp.read_text().split())
    # Without being held the child writes this in ~0.2 s; the reader needs well over a second.
    # Everything but the backlog (1 MiB) and two pipes must have passed the reader first.
    assert ended - started > 0.5, f"the child was not held ({ended - started:.2f} s)"
    assert screen.peak <= screen.limit


@pytest.mark.serial  # how long a child was held, in seconds
def test_a_stalled_reader_costs_screen_lines_only_after_the_stall_time(tmp_path: Path) -> None:
    n = 300_000  # ~7 MB per child: far more than the 1 MiB backlog
    stamps = [tmp_path / f"stamp{i}" for i in range(2)]
    specs = [make_spec(f"c{i}", flood_code(n, "c", stamps[i])) for i in range(2)]
    limit = 1 << 20
    _, screen, reader = run_with_reader(
        specs, {"pause_for": 3.0}, {"stall": 0.5, "limit": limit}, log_dir=str(tmp_path)
    )
    data = bytes(reader.data)
    for stamp in stamps:
        started, ended = map(float, stamp.read_text().split())
        # Held for the stall time (0.5 s), then never again while the reader is paused (3 s).
        assert ended - started < 2.5, f"a child was held {ended - started:.2f} s"
        assert ended < reader.paused_until, "the children waited for the paused reader"
    # The drop is said, with the right count, and every line is either shown or counted.
    reported = sum(int(m) for m in DROP.findall(data))
    assert reported == screen.dropped_lines > 0
    shown = [child_lines(data, f"c{i}", "c") for i in range(2)]
    assert sum(map(len, shown)) + screen.dropped_lines == 2 * n
    for lines in shown:
        assert lines == sorted(lines) and lines[:10] == list(range(10))  # in order, head kept
    # mlaunch's own messages are never dropped; the logs have every line.
    assert data.count(b"process has finished cleanly") == 2
    for i in range(2):
        assert (tmp_path / f"c{i}.log").read_bytes().count(b"\n") == n
    # Memory stays bounded: the backlog never grew past its limit (plus mlaunch's messages).
    assert screen.peak <= limit + 4096


def test_screen_holds_between_its_water_marks_and_stops_holding_when_stalled() -> None:
    now = [0.0]
    r, w = os.pipe()
    try:
        screen = Screen(w, limit=1000, stall=1.0, clock=lambda: now[0])
        assert (screen.high_water, screen.low_water) == (500, 125)
        first = b"x" * 499 + b"\n"
        screen.write(first)  # queued (small writes wait for the loop's flush)
        assert screen.holding()  # at the high-water mark
        now[0] = 0.9
        assert screen.holding()
        now[0] = 1.0
        assert not screen.holding()  # no progress for the stall time: hold nobody
        screen.write(b"y" * 600 + b"\n")  # beyond the limit: dropped, counted
        assert screen.dropped_lines == 1
        screen.write(b"z\n")  # fits: the notice goes first, right where the gap is
        screen.flush()  # the reader takes it all (the pipe has room): progress
        out = os.read(r, 65536)
        notice = (
            b"[WARNING] [launch]: the terminal fell behind: 1 lines (0.0 MB) were not shown;"
            b" the log files have them\n"
        )
        assert out == first + notice + b"z\n"
        assert screen.dropped_lines == 1  # a total over the run; said once
        assert not screen.holding() and screen.backlog == 0
        screen.write(first)
        now[0] = 1.5
        assert screen.holding()  # the reader took something at 1.0: not stalled
        screen.flush()
        assert not screen.holding()  # below the low-water mark: read the children again
        assert os.read(r, 65536) == first
        assert screen.peak <= screen.limit
    finally:
        os.close(r)
        os.close(w)


# --- the guard: one write per loop turn -----------------------------------------------------------


def test_guard_lines_are_batched_one_write_per_turn() -> None:
    r, w = os.pipe()
    os.set_blocking(w, False)
    guard = guards.Guard(-1, w)  # no guard process: the test reads what it would get
    specs = [make_spec(f"n{i}", "", argv=("sleep", "0.3")) for i in range(20)]
    plan = Plan(steps=[Spawn(spec=s) for s in specs])
    sup = Supervisor(plan, Printer(out=bytearray().extend), install_signals=False, guard=guard)
    writes_after_start: list[int] = []
    sup.schedule(0.0, lambda: writes_after_start.append(guard.writes), keeps_alive=False)
    try:
        assert sup.run() == 0
        got = b""
        while chunk := os.read(r, 65536):
            got += chunk
    finally:
        os.close(r)
        if guard.fd >= 0:
            os.close(guard.fd)
    assert writes_after_start == [1]  # twenty spawns, one write
    lines = got.decode().split("\n")
    pids = {str(rec.pid) for rec in sup.states.values()}
    assert {line[1:].split()[0] for line in lines if line.startswith("+")} == pids
    assert {line[1:] for line in lines if line.startswith("-")} == pids
    assert lines[-2:] == ["x", ""]  # the goodbye, once the run has ended everything


# --- the stray sweep ------------------------------------------------------------------------------


def test_tree_finds_descendants_at_any_depth() -> None:
    p = subprocess.Popen(
        ["/bin/sh", "-c", "sleep 30 & echo $!; wait"], stdout=subprocess.PIPE, text=True
    )
    try:
        assert p.stdout is not None
        grandchild = int(p.stdout.readline())
        found = {proc.pid: proc for proc in proctable.tree(os.getpid())}
        assert p.pid in found and grandchild in found
        assert found[grandchild].ppid == p.pid
        assert {q.pid for q in proctable.descendants(os.getpid())} >= {p.pid, grandchild}
    finally:
        p.kill()
        os.kill(grandchild, signal.SIGKILL)
        p.wait(5)


def counting_marker_scans(monkeypatch: object) -> list[str]:
    calls: list[str] = []
    original = proctable.marked

    def marked(run_id: str, procs: object = None) -> list[proctable.ProcInfo]:
        calls.append(run_id)
        return original(run_id, procs)  # type: ignore[arg-type]

    monkeypatch.setattr(proctable, "marked", marked)  # type: ignore[attr-defined]
    return calls


def count_during_run(h: Harness, calls: list[str]) -> list[int]:
    """How many marker scans the supervisor's run made (the harness makes its own after)."""
    seen: list[int] = []
    run = h.sup.run

    def counted() -> int:
        try:
            return run()
        finally:
            seen.append(len(calls))

    h.sup.run = counted  # type: ignore[method-assign]
    return seen


def test_a_clean_shutdown_walks_the_tree_without_scanning_every_process(
    monkeypatch: object,
) -> None:
    calls = counting_marker_scans(monkeypatch)
    up = ("/bin/sh", "-c", "echo up; exec sleep 30")
    h = Harness([make_spec(f"s{i}", "", argv=up) for i in range(3)])
    ups: list[str] = []

    def saw(record: Record) -> None:
        if isinstance(record, Output):
            ups.extend(record.process.label for line in record.data.splitlines() if line == b"up")
            if len(ups) == 3:
                h.shutdown()

    h.sup.records.subscribe(saw)
    during_run = count_during_run(h, calls)
    assert h.run() == 0
    assert not h.sup.strays.escaped, "a child of this process had exited before the run began"
    assert during_run == [0]


@pytest.mark.skipif(shutil.which("setsid") is None, reason="needs setsid(1) from util-linux")
def test_an_orphan_from_before_the_subreaper_is_found_by_its_marker(monkeypatch: object) -> None:
    calls = counting_marker_scans(monkeypatch)

    class LateSubreaper(Strays):
        """Becomes subreaper only after the child has exited: its orphan went to init."""

        def set_subreaper(self, on: bool) -> None:
            if on:
                assert wait_until(self.a_child_has_exited, 10)
            super().set_subreaper(on)

    # The grandchild leaves the child's session (or it would linger in the child's group). The
    # child waits until it has: under load it would otherwise still be in the group when that
    # is stopped, and end as a member of the group instead of as a stray.
    daemonize = (
        'setsid sleep 30 & p=$!; while [ "$(cut -d" " -f6 /proc/$p/stat)" != "$p" ];'
        " do sleep 0.01; done; echo $p; exit 0"
    )
    spec = make_spec("daemonizer", "", argv=("/bin/sh", "-c", daemonize))
    h = Harness([spec], stray_grace=0.3)
    h.sup.strays = LateSubreaper(h.sup.run_id, grace=0.3)
    orphans: list[int] = []
    h.when(b"", lambda label, line: orphans.append(int(line)))
    during_run = count_during_run(h, calls)
    assert h.run() == 0
    assert h.sup.strays.escaped and during_run[0] > 0
    assert orphans and wait_until(lambda: gone(orphans[0]), 5)
    assert "ending stray descendant sleep" in h.text


# --- through the command line -----------------------------------------------------------------------


@pytest.mark.serial  # the reader keeps up only with a core to itself
def test_cli_flood_to_a_pipe_that_keeps_up_loses_nothing(tmp_path: Path) -> None:
    n = 250_000
    launch = tmp_path / "flood.launch.py"
    entries = "".join(
        f"    ExecuteProcess(cmd=[PY, '-c', {textwrap.dedent(flood_code(n, 'fl'))!r}],"
        f" name='w{i}', output='screen'),\n"
        for i in range(4)
    )
    launch.write_text(
        "from launch import LaunchDescription\nfrom launch.actions import ExecuteProcess\n"
        f"PY = {PY!r}\n"
        f"def generate_launch_description():\n  return LaunchDescription([\n{entries}  ])\n"
    )
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / "log"), TMPDIR=str(tmp_path))
    env.pop("MLAUNCH_RUN_ID", None)
    proc = subprocess.Popen(
        [PY, "-m", "mlaunch", str(launch)], stdout=subprocess.PIPE, env=env, cwd=tmp_path
    )
    try:
        assert proc.stdout is not None
        started = time.monotonic()
        data = proc.stdout.read()  # a fast reader: as fast as this thread can copy
        assert proc.wait(30) == 0
        elapsed = time.monotonic() - started
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)
    assert b"fell behind" not in data and b"Traceback" not in data
    for i in range(4):
        label = next(m.decode() for m in re.findall(rb"\[(w%d-\d+)\]" % i, data[:100_000]))
        assert child_lines(data, label, "fl") == list(range(n))
    print(f"CLI: 4 x {n} lines through a pipe in {elapsed:.2f} s, none dropped")
