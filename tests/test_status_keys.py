"""Keys in ``--status``: mlaunch run on a pseudo-terminal, keys typed, the screen read with pyte.

Plus the pieces on their own: decoding the terminal's bytes into keys, the per-process ring of
recent output, the selection and the pane, and the terminal's settings put back on every way
out (a clean exit, Ctrl-C, an exception in the loop, SIGKILL through the guard).
"""

from __future__ import annotations

import os
import re
import signal
import sys
import termios
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import clean_env, mlaunch, wait_for, wait_until
from ptyrun import PtyRun
from test_status import fake_usage, record
from test_supervision import Harness

from mlaunch.engine.keyboard import Keyboard, decode, guard_line, parse_guard_line
from mlaunch.parts.status import StatusView
from mlaunch.parts.status_keys import NOTICE_SECONDS, PANE_HELP, TABLE_HELP

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
        ExecuteProcess(cmd=[{PY!r}, '-c', TALKER], name='talker', output='screen',
                       respawn=True, respawn_delay=0.3),
        # Its stdout goes to its log file only; a respawn would wait a minute.
        ExecuteProcess(cmd=[{PY!r}, '-c', LISTENER], name='listener', output='log',
                       respawn=True, respawn_delay=60.0),
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


def test_selection_moves_and_the_pane_shows_the_selected_process(tmp_path: Path) -> None:
    h = Harness([], log_dir=str(tmp_path))
    view = StatusView(
        h.sup, h.printer, h.control, size=lambda: (100, 30), color=False, sampler=fake_usage
    )
    keys = view.enable_keys()
    for name in ("a-1", "b-2", "c-3"):
        h.sup.states[name] = record(name, "running", pid=1)
    (tmp_path / "b-2.log").write_bytes(b"first\n  indented\n")
    table = view.render()
    assert "> a-1" in table and table.splitlines()[-1] == TABLE_HELP
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
    assert pane[-1] == PANE_HELP
    keys.press("down")  # the pane follows the selection
    assert view.render().splitlines()[0] == "c-3: running, no output yet"
    keys.press("q")
    assert "> c-3" in view.render()
    view.color = True  # with colours the selected label is highlighted (reverse video) too
    assert "\x1b[7m> c-3" in view.render()
    view.close()


def test_a_request_that_cannot_be_done_says_why_in_place_of_the_help(tmp_path: Path) -> None:
    now = [100.0]
    h = Harness([], log_dir=str(tmp_path), clock=lambda: now[0])
    view = StatusView(
        h.sup, h.printer, h.control, size=lambda: (120, 30), color=False, sampler=fake_usage
    )
    keys = view.enable_keys()
    keys.press("x")  # nothing to act on yet: nothing happens
    assert view.render().splitlines()[-1] == TABLE_HELP
    h.sup.states["a-1"] = record("a-1", "finished", outcome="finished cleanly")
    keys.press("x")
    assert view.render().splitlines()[-1] == "a-1 is not running (finished cleanly)"
    now[0] += NOTICE_SECONDS
    assert view.render().splitlines()[-1] == TABLE_HELP
    keys.press("m")  # muting needs no running process
    row = next(line for line in view.render().splitlines() if "a-1" in line)
    assert "finished, muted" in row
    keys.press("u")
    assert "muted" not in view.render()
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


def table_row(screen: str, name: str) -> str:
    """The table's row of the process ``name`` ("" while there is none)."""
    for line in screen.splitlines():
        if line.lstrip("> ").startswith(name + "-"):
            return line
    return ""


def cell(screen: str, name: str, column: int) -> str:
    """One cell of a row, by column (0: process); cells are at least two spaces apart."""
    cells = re.split(r"\s{2,}", table_row(screen, name).lstrip("> "))
    return cells[column] if column < len(cells) else ""


def started(run: PtyRun) -> str:
    """The screen once both processes run, the talker has printed, and the help line shows."""
    return run.wait_screen(
        lambda s: "running" in cell(s, "listener", 1) and "talker says 2" in s and "x stop" in s,
        what="the table with both processes and the help line",
    )


def said(run: PtyRun, name: str) -> list[int]:
    """The numbers the talker's lines printed above the table (not the table's last output)."""
    run.pump(0)
    return [int(n) for n in re.findall(rf"^\[{name}-\d+\] talker says (\d+)$", run.history(), re.M)]


def test_status_keys_select_and_show_last_lines_in_a_terminal(run: PtyRun) -> None:
    screen = started(run)
    assert not run.cooked()  # cbreak while the view runs
    assert table_row(screen, "talker").startswith("> talker")
    assert table_row(screen, "listener").startswith("  listener")
    run.type(b"j")
    run.wait_screen(lambda s: table_row(s, "listener").startswith("> "), what="j moves down")
    run.type(b"\x1b[A")
    run.wait_screen(lambda s: table_row(s, "talker").startswith("> "), what="up moves up")
    run.type(b"\x1b[B")
    run.wait_screen(lambda s: table_row(s, "listener").startswith("> "), what="down moves down")
    # The listener's stdout goes to its log file only (the table shows its last line), yet its
    # pane shows it.
    assert "[listener-2] listener ready" not in run.history()
    run.type(b"l")
    screen = run.wait_screen("listener-2: running, its last 1 lines", what="the listener's pane")
    assert "Esc/q back" in screen.splitlines()[-1] or "Esc/q back" in screen
    pane = screen[screen.index("listener-2: running") :].splitlines()
    assert pane[1] == "listener ready"
    run.type(b"k")  # the pane follows the selection, and is kept up to date
    screen = run.wait_screen("talker-1: running, its last", what="the talker's pane")
    shown = [
        int(line.split()[-1]) for line in screen.splitlines() if line.startswith("talker says")
    ]
    run.wait_screen(
        lambda s: f"talker says {max(shown) + 2}" in s[s.find("talker-1: running") :],
        what="the pane follows new output",
    )
    run.type(b"\x1b")
    run.wait_screen(lambda s: "last output" in s and "Esc/q" not in s, what="Esc: the table")
    run.type(b"\r")
    run.wait_screen("talker-1: running, its last", what="Enter: the pane again")
    run.type(b"q")
    run.wait_screen(lambda s: "last output" in s, what="q: the table")
    # Ctrl-C typed on the terminal is still the usual shutdown, and the terminal is put back.
    run.type(b"\x03")
    assert run.wait() == 130
    assert run.cooked()
    assert "user interrupted with SIGINT" in run.history()


def test_stop_keeps_it_down_and_start_brings_it_back(run: PtyRun) -> None:
    screen = started(run)
    pid = cell(screen, "talker", 2)
    run.type(b"x")  # the talker is selected: stopped, and its respawn (0.3 s) does not fight it
    run.wait_screen(
        lambda s: cell(s, "talker", 1) == "stopped by the user", what="the row says stopped"
    )
    history = run.history()
    assert "[talker-1]: stop asked by the user (--status keys)" in history
    assert re.search(r"\[talker-1\]: process stopped by the user \[pid \d+, ", history), history
    assert "restart 1" not in history
    assert not wait_until(lambda: "running" in cell(run.now(), "talker", 1), 1.5)
    run.type(b"x")  # stopping it again cannot be done: the help line says why
    run.wait_screen("talker-1 is not running (stopped by the user)", what="the notice")
    run.type(b"s")
    screen = run.wait_screen(
        lambda s: cell(s, "talker", 1) == "running" and cell(s, "talker", 4) == "1",
        what="started again, one restart",
    )
    assert cell(screen, "talker", 2) != pid
    assert "[talker-1]: start asked by the user (--status keys)" in run.history()
    run.type(b"\x03")
    assert run.wait() == 130
    assert run.cooked()


def test_restart_keeps_the_label_counts_one_and_skips_the_respawn_delay(run: PtyRun) -> None:
    screen = started(run)
    pid = cell(screen, "listener", 2)
    run.type(b"jr")  # the listener respawns after 60 s; a restart is at once
    screen = run.wait_screen(
        lambda s: cell(s, "listener", 4) == "1" and cell(s, "listener", 2) not in ("", "-", pid),
        timeout=15,
        what="the listener restarted with a new pid",
    )
    assert cell(screen, "listener", 1) == "running"
    history = run.history()
    assert "[listener-2]: restart asked by the user (--status keys)" in history
    assert "[listener-2]: process stopped by the user for a restart" in history
    assert "restart 1" not in history  # no respawn was scheduled
    assert len(re.findall(r"\[listener-2\]: process started with pid", history)) == 2
    run.type(b"\x03")
    assert run.wait() == 130


def test_mute_hides_the_output_from_the_screen_but_not_from_its_log(
    run: PtyRun, tmp_path: Path
) -> None:
    started(run)
    run.type(b"m")
    run.wait_screen(lambda s: "muted" in cell(s, "talker", 1), what="the row says muted")
    assert "[talker-1]: output muted by the user (--status keys)" in run.history()
    before = max(said(run, "talker"))
    log = tmp_path / "logs" / "latest" / "talker-1.log"

    def logged() -> list[int]:
        return [int(n) for n in re.findall(rb"^talker says (\d+)$", log.read_bytes(), re.M)]

    wait_for(lambda: max(logged()) >= before + 4, 10, "the log to go on")
    assert max(said(run, "talker")) <= before + 1  # a line on its way as m was typed, at most
    run.type(b"u")
    run.wait_screen(lambda s: "muted" not in cell(s, "talker", 1), what="unmuted")
    wait_for(lambda: max(said(run, "talker")) > before + 4, 10, "lines again")
    assert "[talker-1]: output unmuted by the user (--status keys)" in run.history()
    run.type(b"\x03")
    assert run.wait() == 130


def test_terminal_is_put_back_when_mlaunch_is_killed(run: PtyRun) -> None:
    run.wait_screen("x stop", what="the help line")
    assert not run.cooked()
    os.kill(run.pid, signal.SIGKILL)
    assert run.wait() == -signal.SIGKILL
    # The guard puts the terminal's settings back (then ends the processes).
    wait_for(run.cooked, 10, "the guard to put the terminal back")


def test_terminal_is_put_back_after_sigterm(run: PtyRun) -> None:
    run.wait_screen("x stop", what="the help line")
    os.kill(run.pid, signal.SIGTERM)
    assert run.wait() == 143
    assert run.cooked()


def test_keys_need_a_terminal_on_stdin(tmp_path: Path, launch_file: Path) -> None:
    """stdout a terminal but stdin not (``< /dev/null``): the table, no keys, no help line."""
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"), TERM="xterm")
    argv = ["/bin/sh", "-c", 'exec "$@" < /dev/null', "sh", *mlaunch(str(launch_file), "--status")]
    proc = PtyRun(argv, env=env)
    try:
        screen = proc.wait_screen(lambda s: "talker says 1" in s and "last output" in s)
        assert "x stop" not in screen and "> talker" not in screen
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
        from mlaunch.engine.keyboard import Keyboard
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


@pytest.fixture
def shell(tmp_path: Path) -> Iterator[PtyRun]:
    """An interactive bash on a pty (job control on, no line editing), at its prompt."""
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"), TERM="xterm", PS1="$ ")
    proc = PtyRun(["/bin/bash", "--norc", "--noprofile", "--noediting", "-i"], env=env)
    try:
        proc.wait_screen("$", what="the prompt")
        yield proc
    finally:
        proc.close()


def end_in_shell(shell: PtyRun) -> None:
    """Ctrl-C to the launch in the foreground; the shell gets a cooked terminal back."""
    shell.type(b"\x03")
    shell.wait_screen("Summary: 2 processes", what="the run's end")
    wait_for(shell.cooked, 10, "the terminal put back")
    shell.type(b"exit\n")
    shell.wait()


def test_ctrl_z_and_fg_take_the_keys_up_again(shell: PtyRun, launch_file: Path) -> None:
    """Job control under a real shell: Ctrl-Z stops mlaunch and the shell gets its terminal
    back; after fg the view is in cbreak mode again and the keys work."""
    shell.type(" ".join(mlaunch(str(launch_file), "--status")).encode() + b"\n")
    shell.wait_screen(lambda s: "x stop" in s and "talker says 2" in s, what="the view")
    assert not shell.cooked()
    shell.type(b"\x1a")
    shell.wait_screen("Stopped", what="the shell's word that mlaunch stopped")
    wait_for(shell.cooked, 10, "the shell's own terminal mode")
    shell.type(b"fg\n")
    wait_for(lambda: not shell.cooked(), 10, "cbreak mode again")
    shell.type(b"j")
    shell.wait_screen(lambda s: table_row(s, "listener").startswith("> "), what="keys work again")
    end_in_shell(shell)


def test_started_in_the_background_the_keys_wait_for_fg(shell: PtyRun, launch_file: Path) -> None:
    """``mlaunch FILE --status &``: the terminal is the shell's (no cbreak, no help line) until
    fg brings mlaunch to the foreground."""
    shell.type(" ".join(mlaunch(str(launch_file), "--status")).encode() + b" &\n")
    screen = shell.wait_screen(lambda s: "talker says 3" in s and "last output" in s)
    assert "x stop" not in screen
    assert shell.cooked()
    shell.type(b"fg\n")
    shell.wait_screen("x stop", what="the help line once in the foreground")
    assert not shell.cooked()
    end_in_shell(shell)


def test_a_hung_up_terminal_is_no_longer_read() -> None:
    """After a hangup the terminal is readable forever with nothing to read: selecting it
    again would spin the loop through the whole shutdown."""
    master, slave = os.openpty()
    h = Harness([])
    keyboard = Keyboard(h.sup.selector, lambda key: None, fd=slave)
    keyboard.foreground = lambda: True  # type: ignore[method-assign]
    try:
        assert keyboard.start() and keyboard.reading
        os.close(master)  # the terminal window closes
        ready = h.sup.selector.select(5)
        assert [key.fd for key, _ in ready] == [slave]
        for key, _ in ready:
            key.data(key.fd)
        assert not keyboard.reading
        assert h.sup.selector.select(0) == []
        keyboard.close()
    finally:
        os.close(slave)


def test_a_closed_terminal_window_is_a_sighup_shutdown(run: PtyRun) -> None:
    started(run)
    run.hang_up()
    assert run.wait() == 129


def test_a_narrow_terminal_drops_whole_columns_instead_of_cutting_numbers() -> None:
    h = Harness([])
    width = [80]
    view = StatusView(
        h.sup, h.printer, h.control, size=lambda: (width[0], 30), color=False, sampler=fake_usage
    )
    view.enable_keys()
    h.sup.states["robot_state_publisher-1"] = record(
        "robot_state_publisher-1", "running", pid=12345
    )
    h.sup.states["spawner-2"] = record("spawner-2", "stopped", outcome="stopped by the user")
    view.usage = fake_usage({12345: []})
    view.last_line["robot_state_publisher-1"] = b"publishing the robot description"
    wide = view.render().splitlines()
    assert wide[1].split() == ["process", "state", "pid", "uptime", "restarts", "cpu"]
    assert "12345" in wide[3] and "12%" in wide[3] and "stopped by the user" in wide[4]
    assert all(len(line) <= 79 and "\u2026" not in line for line in wide)
    width[0] = 120
    assert "memory" in view.render() and "last output" in view.render()
    view.close()
