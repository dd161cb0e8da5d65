"""Faults injected into real ``python -m mlaunch`` runs: signals to mlaunch itself, its death by
SIGKILL, floods and a terminal nobody reads. Each run checks that nothing of it is left.

Children print ``up <run id> <pid>`` so the test knows the run's marker and every pid; it waits
for those lines (a reader thread and a deadline), never for a sleep.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import IO

import pytest
from procutil import wait_until

from mlaunch.engine import proctable

PY = sys.executable

UP = "import os; print('up', os.environ.get('MLAUNCH_RUN_ID'), os.getpid(), flush=True)"
SLEEPER = UP + "\nimport time; time.sleep(60)"
STUBBORN = (
    "import signal\n"
    "signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
    "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n" + SLEEPER
)
# A child that starts a grandchild in a session of its own (escaping the child's group).
ESCAPER = (
    "import subprocess, sys\n"
    f"subprocess.Popen([sys.executable, '-c', {SLEEPER!r}], start_new_session=True)\n" + SLEEPER
)


def alive(pid: int) -> bool:
    """Running (a zombie waiting for init to reap it counts as gone)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            data = f.read()
    except OSError:
        return False
    return data[data.rfind(b")") + 2 : data.rfind(b")") + 3] not in (b"Z", b"X")


def write_launch(tmp_path: Path, entries: list[str]) -> Path:
    path = tmp_path / "faults.launch.py"
    lines = [
        "from launch import LaunchDescription",
        "from launch.actions import ExecuteProcess, Shutdown",
        f"PY = {PY!r}",
        "",
        "def generate_launch_description():",
        "    return LaunchDescription([",
        *(f"        {entry}," for entry in entries),
        "    ])",
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def proc(code: str, name: str, **extra: object) -> str:
    """An ExecuteProcess entry for the launch file: ``sys.executable -c code``."""
    args = "".join(f", {k}={v!r}" for k, v in extra.items())
    return f"ExecuteProcess(cmd=[PY, '-c', {code!r}], name={name!r}, output='screen'{args})"


class Mlaunch:
    """``python -m mlaunch FILE`` as a subprocess, its stdout read line by line by a thread."""

    def __init__(
        self, tmp_path: Path, launch: Path, *args: str, stdout: int | IO[bytes] | None = None
    ) -> None:
        self.tmp = tmp_path / "tmp"
        self.tmp.mkdir(exist_ok=True)
        self.log_dir = tmp_path / "log"
        env = dict(os.environ, TMPDIR=str(self.tmp), ROS_LOG_DIR=str(self.log_dir))
        env.pop("MLAUNCH_RUN_ID", None)
        self.popen = subprocess.Popen(
            [PY, "-m", "mlaunch", str(launch), *args],
            stdout=subprocess.PIPE if stdout is None else stdout,
            stderr=subprocess.PIPE,
            env=env,
            cwd=tmp_path,
        )
        self.lines: list[str] = []
        self.reader: threading.Thread | None = None
        if stdout is None:
            self.reader = threading.Thread(target=self._read, daemon=True)
            self.reader.start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for raw in self.popen.stdout:
            self.lines.append(raw.decode("utf-8", "replace").rstrip("\n"))

    def ups(self) -> list[tuple[str, int]]:
        """(run id, pid) of every child that said ``up``."""
        out = []
        for line in list(self.lines):
            words = line.split()
            if len(words) == 4 and words[1] == "up":
                out.append((words[2], int(words[3])))
        return out

    def wait_ups(self, n: int, timeout: float = 15.0) -> list[tuple[str, int]]:
        assert wait_until(lambda: len(self.ups()) >= n, timeout), "\n".join(self.lines)
        return self.ups()

    def wait(self, timeout: float = 20.0) -> int:
        code = self.popen.wait(timeout)
        if self.reader is not None:
            self.reader.join(5)
        return code

    def stderr(self) -> str:
        assert self.popen.stderr is not None
        return self.popen.stderr.read().decode("utf-8", "replace")

    @property
    def text(self) -> str:
        return "\n".join(self.lines)

    def close(self) -> None:
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(5)
        for stream in (self.popen.stdout, self.popen.stderr):
            if stream is not None:
                stream.close()


def assert_nothing_left(run_id: str, pids: list[int], timeout: float = 10.0) -> None:
    def clean() -> bool:
        return not any(alive(pid) for pid in pids) and not proctable.marked(run_id)

    ok = wait_until(clean, timeout)
    leftovers = [pid for pid in pids if alive(pid)] + [p.pid for p in proctable.marked(run_id)]
    for pid in leftovers:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    assert ok, f"left running: {leftovers}"


# --- mlaunch itself dies -------------------------------------------------------------------------


def test_mlaunch_killed_with_sigkill_leaves_nothing_behind(tmp_path: Path) -> None:
    launch = write_launch(
        tmp_path,
        [
            proc(SLEEPER, "plain", sigkill_timeout=0.5),
            proc(STUBBORN, "stubborn", sigkill_timeout=0.5),  # the guard must SIGKILL it
            proc(ESCAPER, "escaper", sigkill_timeout=0.5),  # its grandchild is in another session
        ],
    )
    m = Mlaunch(tmp_path, launch)
    try:
        ups = m.wait_ups(4)
        run_id = ups[0][0]
        assert all(r == run_id for r, _ in ups)
        assert len(list(m.tmp.glob("mlaunch-*"))) == 1  # the private temp dir exists
        m.popen.send_signal(signal.SIGKILL)
        assert m.wait() == -signal.SIGKILL
        started = time.monotonic()
        assert_nothing_left(run_id, [pid for _, pid in ups])
        print(f"guard ended the run {time.monotonic() - started:.2f} s after mlaunch died")
        assert wait_until(lambda: not list(m.tmp.glob("mlaunch-*")), 5), "temp dir left"
        err = m.stderr()
        assert "died without stopping its processes; ended 4 of its processes" in err, err
    finally:
        m.close()


def test_sigint_to_mlaunch_stops_everything_and_exits_130(tmp_path: Path) -> None:
    launch = write_launch(tmp_path, [proc(SLEEPER, "a"), proc(ESCAPER, "b")])
    m = Mlaunch(tmp_path, launch)
    try:
        ups = m.wait_ups(3)
        m.popen.send_signal(signal.SIGINT)
        assert m.wait() == 130
        assert "user interrupted with SIGINT" in m.text
        assert_nothing_left(ups[0][0], [pid for _, pid in ups], timeout=2)
        assert "Summary: 2 processes" in m.text  # more than one process: the table is printed
    finally:
        m.close()


def test_sigterm_to_mlaunch_exits_143(tmp_path: Path) -> None:
    m = Mlaunch(tmp_path, write_launch(tmp_path, [proc(SLEEPER, "a")]))
    try:
        ups = m.wait_ups(1)
        m.popen.send_signal(signal.SIGTERM)
        assert m.wait() == 143
        assert_nothing_left(ups[0][0], [pid for _, pid in ups], timeout=2)
    finally:
        m.close()


def test_second_sigint_kills_at_once(tmp_path: Path) -> None:
    launch = write_launch(
        tmp_path, [proc(STUBBORN, "stubborn", sigterm_timeout=30.0, sigkill_timeout=30.0)]
    )
    m = Mlaunch(tmp_path, launch)
    try:
        ups = m.wait_ups(1)
        m.popen.send_signal(signal.SIGINT)
        assert wait_until(lambda: "user interrupted with SIGINT" in m.text)
        m.popen.send_signal(signal.SIGINT)
        assert m.wait(timeout=5) == 130
        assert "stopping now: SIGKILL to every process" in m.text
        assert_nothing_left(ups[0][0], [pid for _, pid in ups], timeout=2)
    finally:
        m.close()


# --- exit status ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("entries", "expected"),
    [
        ([proc("print('done')", "job")], 0),
        ([proc(SLEEPER, "other"), proc("import sys; sys.exit(4)", "boss", required=True)], 1),
        ([proc(SLEEPER, "other"), proc("pass", "boss", on_exit="SHUTDOWN")], 0),
    ],
    ids=["clean", "required-failed", "required-clean"],
)
def test_exit_status(tmp_path: Path, entries: list[str], expected: int) -> None:
    entries = [e.replace("on_exit='SHUTDOWN'", "on_exit=Shutdown()") for e in entries]
    m = Mlaunch(tmp_path, write_launch(tmp_path, entries))
    try:
        assert m.wait() == expected, m.text + m.stderr()
        if expected == 1:
            assert "shutting down: required process boss-2 exited with status 4" in m.text
        if len(entries) == 1:
            assert "Summary" not in m.text  # one clean process: no table
    finally:
        m.close()


# --- output faults -------------------------------------------------------------------------------


def peak_rss_until_exit(pid: int) -> float:
    """The process's peak RSS in MiB (VmHWM), read every 10 ms until it exits (not reaped).

    Not wait4's ru_maxrss: a child started with vfork counts the RSS its parent (this pytest,
    grown by earlier tests) had when it called exec.
    """
    peak = 0
    while not os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT):
        try:
            with open(f"/proc/{pid}/status", "rb") as f:
                for line in f:
                    if line.startswith(b"VmHWM:"):
                        peak = max(peak, int(line.split()[1]))
        except OSError:
            break
        time.sleep(0.01)  # the sampling period, not a synchronisation
    return peak / 1024


def test_flood_through_the_cli_arrives_complete_with_bounded_memory(tmp_path: Path) -> None:
    n = 1_000_000
    code = (
        "import sys\n"
        "w = sys.stdout.buffer.write\n"
        f"for s in range(0, {n}, 20000):\n"
        "    w(b''.join(b'flood line %d\\n' % i for i in range(s, s + 20000)))\n"
    )
    out = tmp_path / "screen.txt"
    with out.open("wb") as f:
        m = Mlaunch(tmp_path, write_launch(tmp_path, [proc(code, "flood")]), stdout=f)
        try:
            started = time.monotonic()
            peak = peak_rss_until_exit(m.popen.pid)
            elapsed = time.monotonic() - started
            assert m.wait() == 0
        finally:
            m.close()
    data = out.read_bytes()
    assert data.count(b"\n[flood-1] flood line ") == n
    assert f"[flood-1] flood line {n - 1}\n".encode() in data
    print(f"CLI flood: {n / elapsed:,.0f} lines/s end to end, mlaunch peak RSS {peak:.0f} MiB")
    assert peak < 150, f"mlaunch grew to {peak:.0f} MiB"
    logs = list((tmp_path / "log").glob("*/flood-1.log"))
    assert logs and logs[0].read_bytes().count(b"\n") == n


def test_a_stdout_nobody_reads_never_blocks_the_children(tmp_path: Path) -> None:
    done = tmp_path / "done"
    code = (
        "import pathlib, sys\n"
        "w = sys.stdout.buffer.write\n"
        "for s in range(0, 400000, 20000):\n"
        "    w(b''.join(b'chatter %d\\n' % i for i in range(s, s + 20000)))\n"
        "sys.stdout.flush()\n"
        f"pathlib.Path({str(done)!r}).write_text('ok')\n"
    )
    m = Mlaunch(tmp_path, write_launch(tmp_path, [proc(code, "chatty")]), stdout=subprocess.PIPE)
    try:
        # Nobody reads mlaunch's stdout (a 64 KiB pipe), yet the child writes 6 MB and finishes.
        assert wait_until(done.exists, 20), "the child was blocked by a stuck terminal"
        out, _ = m.popen.communicate(timeout=20)
        assert m.popen.returncode == 0
        assert b"the terminal fell behind" in out
        logs = list((tmp_path / "log").glob("*/chatty-1.log"))
        assert logs and logs[0].read_bytes().count(b"\n") == 400_000
    finally:
        m.close()


# --- start-up cost -------------------------------------------------------------------------------


PROBE = """
import re, sys
from mlaunch.engine import spawning
heavy = ("rich", "psutil", "ctypes", "subprocess")
first, patterns = [], []
compile_pattern = re._compile
def compiled(pattern, flags):  # the regular expressions mlaunch's own code compiles
    caller = sys._getframe(1)
    while caller is not None and caller.f_code.co_filename.endswith(("/re/__init__.py",)):
        caller = caller.f_back
    if caller is not None and "/mlaunch/" in caller.f_code.co_filename and not first:
        patterns.append(f"{caller.f_code.co_filename}:{caller.f_lineno}")
    return compile_pattern(pattern, flags)
re._compile = compiled
original = spawning.start
def spy(*args, **kwargs):
    if not first:
        first.append([m for m in heavy if m in sys.modules])
    return original(*args, **kwargs)
spawning.start = spy
from mlaunch.cli import main
code = main([sys.argv[1]])
print("AT-FIRST-SPAWN", first[0], "AT-END", [m for m in heavy[:2] if m in sys.modules])
print("PATTERNS-BEFORE-FIRST-SPAWN", patterns)
"""


def test_a_plain_run_imports_nothing_heavy_before_the_first_child(tmp_path: Path) -> None:
    launch = write_launch(tmp_path, [proc("print('hi')", "one")])
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / "log"))
    result = subprocess.run(
        [PY, "-c", PROBE, str(launch)], capture_output=True, text=True, env=env, timeout=60
    )
    assert result.returncode == 0, result.stderr
    assert "AT-FIRST-SPAWN [] AT-END []" in result.stdout, result.stdout
    # No regular expression of mlaunch's is compiled on the way (~0.4 ms each).
    assert "PATTERNS-BEFORE-FIRST-SPAWN []" in result.stdout, result.stdout


def test_guard_start_up_cost(tmp_path: Path) -> None:
    code = (
        "import time\n"
        "from mlaunch.engine.guard import Guard\n"
        "costs = []\n"
        "for i in range(5):\n"
        "    t = time.perf_counter(); g = Guard.start(f'probe-{i}')\n"
        "    costs.append(time.perf_counter() - t); g.close()\n"
        "print(sorted(costs)[2] * 1000)\n"
    )
    result = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    median_ms = float(result.stdout)
    print(f"guard start-up (fork) in a fresh interpreter: {median_ms:.2f} ms")
    assert median_ms < 20
