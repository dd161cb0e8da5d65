"""Keys in ``--status``: mlaunch run on a pseudo-terminal, keys typed, the screen read with pyte.

Plus the pieces on their own: decoding the terminal's bytes into keys, the per-process ring of
recent output, the selection and the pane, and the terminal's settings put back on every way
out (a clean exit, Ctrl-C, an exception in the loop, SIGKILL through the guard).
"""

from __future__ import annotations

import os
import signal
import sys
import termios
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import clean_env, mlaunch, wait_for
from ptyrun import PtyRun
from test_status import fake_usage, record
from test_supervision import Harness

from mlaunch.run.keyboard import Keyboard, decode, guard_line, parse_guard_line
from mlaunch.run.status import StatusView
from mlaunch.run.status_keys import Recent

PY = sys.executable

TWO = f"""
from launch import LaunchDescription
from launch.actions import ExecuteProcess

TALKER = '''
import itertools, sys, time
for i in itertools.count():
    print("talker says", i, flush=True)
    time.sleep(0.2)
'''
LISTENER = '''
import time
print("listener ready", flush=True)
time.sleep(600)
'''

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[{PY!r}, '-c', TALKER], name='talker', output='log'),
        ExecuteProcess(cmd=[{PY!r}, '-c', LISTENER], name='listener', output='screen'),
    ])
"""


# --- the pieces ----------------------------------------------------------------------------------


def test_decode_keys_and_sequences() -> None:
    assert decode(b"jk") == (["j", "k"], b"")
    assert decode(b"\x1b[A\x1b[B\x1bOA") == (["up", "down", "up"], b"")
    assert decode(b"\x1b") == (["esc"], b"")
    assert decode(b"\x1bq") == (["esc", "q"], b"")  # Esc typed just before q
    assert decode(b"\r") == (["enter"], b"")
    # A sequence cut by the read is kept for the next one, and completed by it.
    keys, rest = decode(b"j\x1b[")
    assert (keys, rest) == (["j"], b"\x1b[")
    assert decode(rest + b"B") == (["down"], b"")
    # Unknown sequences (F5, mouse reports) are read and ignored; UTF-8 arrives whole.
    assert decode(b"\x1b[15~x") == (["x"], b"")
    assert decode("é".encode()[:1]) == ([], "é".encode()[:1])
    assert decode("é".encode()) == (["é"], b"")
    assert decode(b"\x01") == ([], b"")  # control characters other than Enter mean nothing


def test_guard_line_carries_the_settings_back() -> None:
    master, slave = os.openpty()
    try:
        attrs = termios.tcgetattr(slave)
        line = guard_line(attrs)
        assert line.startswith(b"t ") and line.endswith(b"\n")
        assert parse_guard_line(line.rstrip(b"\n")) == attrs
        assert parse_guard_line(b"t") is None
    finally:
        os.close(master)
        os.close(slave)


def test_recent_keeps_the_last_lines_within_its_bound() -> None:
    recent = Recent(limit=100)
    for i in range(50):
        recent.add("a", b"line %d\n" % i)
    recent.add("b", b"one\ntwo\n")
    assert recent.lines("a", 3) == [b"line 47", b"line 48", b"line 49"]
    assert recent.lines("b", 10) == [b"one", b"two"]
    assert recent.lines("c", 10) == []
    assert sum(len(line) + 1 for line in recent.lines("a", 1000)) <= 100 + 8
    recent.add("a", b"x" * 500 + b"\nlast\n")  # one chunk bigger than the bound: its tail
    assert recent.lines("a", 2) == [b"line 49", b"last"]


def test_selection_moves_and_the_pane_shows_the_selected_process() -> None:
    h = Harness([])
    view = StatusView(h.sup, size=lambda: (100, 30), color=False, sampler=fake_usage)
    keys = view.enable_keys()

    for name in ("a-1", "b-2", "c-3"):
        h.sup.records[name] = record(name, "running", pid=1)
    keys.saw_output("b-2", b"first\n  indented\n")
    table = view.render()
    assert "> a-1" in table and "keys:" in table.splitlines()[-1]
    for key in ("down", "j"):
        keys.press(key)
    assert keys.current() == "c-3"
    keys.press("down")  # wraps around
    keys.press("k")
    keys.press("up")
    assert keys.current() == "b-2"
    assert "> b-2" in view.render()
    keys.press("l")
    pane = view.render().splitlines()
    assert pane[0] == "b-2: running, its last 2 lines"
    assert pane[1:3] == ["first", "  indented"]
    assert "Esc or q" in pane[-1]
    keys.press("down")  # the pane follows the selection
    assert view.render().splitlines()[0] == "c-3: running, no output yet"
    keys.press("q")
    assert "> c-3" in view.render()
    view.close()


def test_keyboard_sets_cbreak_and_puts_the_terminal_back() -> None:
    master, slave = os.openpty()
    told: list[bytes] = []
    h = Harness([])
    got: list[str] = []
    # The test process is not the pty's foreground group: pretend it is (the seam is the
    # question, asked of this pty).
    keyboard = Keyboard(h.sup.selector, got.append, fd=slave, tell_guard=told.append)
    keyboard.foreground = lambda: True  # type: ignore[method-assign]
    before = termios.tcgetattr(slave)
    try:
        assert keyboard.start()
        modes = termios.tcgetattr(slave)[3]
        assert not modes & termios.ICANON and not modes & termios.ECHO
        assert modes & termios.ISIG  # Ctrl-C stays the terminal's SIGINT
        assert told == [guard_line(before)]
        os.write(master, b"j\x1b[A")
        for key, _ in h.sup.selector.select(5):
            key.data(key.fd)
        assert got == ["j", "up"]
        keyboard.close()
        assert termios.tcgetattr(slave) == before
        assert told[-1] == b"t\n"
        keyboard.close()  # twice is fine
    finally:
        os.close(master)
        os.close(slave)


def test_keyboard_is_left_alone_in_the_background() -> None:
    master, slave = os.openpty()
    h = Harness([])
    keyboard = Keyboard(h.sup.selector, lambda key: None, fd=slave)
    before = termios.tcgetattr(slave)
    try:
        assert not keyboard.start()  # this process does not own the pty
        assert termios.tcgetattr(slave) == before
        keyboard.close()
    finally:
        os.close(master)
        os.close(slave)


# --- mlaunch on a pseudo-terminal ----------------------------------------------------------------


@pytest.fixture
def launch_file(tmp_path: Path) -> Path:
    path = tmp_path / "two.launch.py"
    path.write_text(textwrap.dedent(TWO))
    return path


@pytest.fixture
def run(tmp_path: Path, launch_file: Path) -> Iterator[PtyRun]:
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"), TERM="xterm")
    proc = PtyRun(mlaunch(str(launch_file), "--status"), env=env, columns=120, lines=30)
    try:
        yield proc
    finally:
        proc.close()


def table_row(screen: str, name: str) -> str | None:
    for line in screen.splitlines():
        if line.lstrip("> ").startswith(name):
            return line
    return None


def test_status_keys_select_and_show_last_lines_in_a_terminal(run: PtyRun) -> None:
    screen = run.wait_screen(
        lambda s: "listener ready" in s and "talker says 2" in s and "keys:" in s,
        what="the table with both processes and the help line",
    )
    assert not run.cooked()  # cbreak while the view runs
    assert (table_row(screen, "talker") or "").startswith("> talker")
    assert (table_row(screen, "listener") or "").startswith("  listener")
    run.type(b"j")
    run.wait_screen(
        lambda s: (table_row(s, "listener") or "").startswith("> listener"), what="j moves down"
    )
    run.type(b"\x1b[A")
    run.wait_screen(
        lambda s: (table_row(s, "talker") or "").startswith("> talker"), what="up moves up"
    )
    # The talker's output goes to its log only (output='log'), yet its pane shows it.
    run.type(b"l")
    screen = run.wait_screen("talker-1: running, its last", what="the pane")
    assert "keys: Esc or q back" in screen
    pane = screen[screen.index("talker-1: running") :]
    assert "talker says" in pane and "process" not in pane.splitlines()[1]
    said = [int(line.split()[-1]) for line in pane.splitlines() if line.startswith("talker says")]
    # Kept up to date while it is open.
    run.wait_screen(
        lambda s: f"talker says {max(said) + 2}" in s[s.find("talker-1: running") :],
        what="the pane follows new output",
    )
    run.type(b"\x1b")
    run.wait_screen(lambda s: "last output" in s and "Esc or q" not in s, what="Esc: the table")
    run.type(b"l")
    run.wait_screen("talker-1: running, its last", what="the pane again")
    run.type(b"q")
    run.wait_screen(lambda s: "last output" in s, what="q: the table")
    # Ctrl-C typed on the terminal is still the usual shutdown, and the terminal is put back.
    run.type(b"\x03")
    assert run.wait() == 130
    assert run.cooked()
    assert "user interrupted with SIGINT" in run.history()


def test_terminal_is_put_back_when_mlaunch_is_killed(run: PtyRun) -> None:
    run.wait_screen("keys:", what="the help line")
    assert not run.cooked()
    os.kill(run.pid, signal.SIGKILL)
    assert run.wait() == -signal.SIGKILL
    # The guard puts the terminal's settings back (then ends the processes).
    wait_for(run.cooked, 10, "the guard to put the terminal back")


def test_terminal_is_put_back_after_sigterm(run: PtyRun) -> None:
    run.wait_screen("keys:", what="the help line")
    os.kill(run.pid, signal.SIGTERM)
    assert run.wait() == 143
    assert run.cooked()


def test_keys_need_a_terminal_on_stdin(tmp_path: Path, launch_file: Path) -> None:
    """stdout a terminal but stdin not (``< /dev/null``): the table, no keys, no help line."""
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"), TERM="xterm")
    argv = ["/bin/sh", "-c", 'exec "$@" < /dev/null', "sh", *mlaunch(str(launch_file), "--status")]
    proc = PtyRun(argv, env=env)
    try:
        screen = proc.wait_screen(lambda s: "listener ready" in s and "last output" in s)
        assert "keys:" not in screen and "> talker" not in screen
        assert proc.cooked()
        proc.type(b"\x03")
        assert proc.wait() == 130
    finally:
        proc.close()


def test_terminal_is_put_back_when_the_program_fails_without_closing(tmp_path: Path) -> None:
    """The atexit fallback: an exception that skips every close still leaves a cooked terminal."""
    code = textwrap.dedent(
        """
        import selectors
        from mlaunch.run.keyboard import Keyboard
        keyboard = Keyboard(selectors.DefaultSelector(), print)
        assert keyboard.start()
        print("cbreak now", flush=True)
        import select; select.select([0], [], [], 10)
        raise RuntimeError("a bug in the loop")
        """
    )
    proc = PtyRun([PY, "-c", code], env=clean_env())
    try:
        proc.wait_screen("cbreak now")
        assert not proc.cooked()
        proc.type(b"x")
        assert proc.wait() == 1
        assert "RuntimeError: a bug in the loop" in proc.history()
        assert proc.cooked()
    finally:
        proc.close()
