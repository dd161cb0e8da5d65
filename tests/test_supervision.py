"""The supervisor driven in-process: restart and exit policy, the stop ladder, no orphans, no lost output.

Each test builds a Plan (directly, or from a launch file written to tmp_path), runs a Supervisor
with a Printer that collects the screen bytes, and acts from inside the loop when a child says
something (a printer hook) - so nothing waits on a sleep. After every run the test checks that no
process of the run is left, found by the run's marker in /proc.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import stat
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from procutil import wait_until

from mlaunch.engine import proctable
from mlaunch.engine.logfiles import LogFile
from mlaunch.engine.output import Printer
from mlaunch.engine.process import (
    MAX_PARTIAL,
    Process,
    core_dump_hint,
    expand_core_pattern,
    utf8_safe_cut,
)
from mlaunch.engine.process_state import FAILED, FINISHED, GAVE_UP
from mlaunch.engine.respawn import STABLE_UPTIME, respawn_delay
from mlaunch.engine.screen import Screen
from mlaunch.engine.supervisor import Supervisor
from mlaunch.parts.control import Control
from mlaunch.plan.records import Exited, FailedToStart, Output, Record, Started
from mlaunch.plan.steps import Plan, ProcessSpec, RespawnPolicy, Spawn

if TYPE_CHECKING:
    from mlaunch.plan.records import ProcessView

PY = sys.executable


def make_spec(
    label: str,
    code: str,
    *,
    respawn: RespawnPolicy | None = None,
    required: bool = False,
    sigterm: float = 5.0,
    sigkill: float = 5.0,
    output: str = "screen",
    cwd: str | None = None,
    argv: tuple[str, ...] | None = None,
) -> ProcessSpec:
    return ProcessSpec(
        label=label,
        argv=argv or (PY, "-c", textwrap.dedent(code)),
        env=dict(os.environ),
        env_changes={},
        cwd=cwd,
        output=output,
        respawn=respawn or RespawnPolicy(),
        sigterm_timeout=sigterm,
        sigkill_timeout=sigkill,
        required=required,
    )


class Harness:
    """A Supervisor over a plan, with a collecting screen and hooks on child output."""

    def __init__(
        self,
        plan: Plan | list[ProcessSpec],
        *,
        log_dir: str | None = None,
        rotate_bytes: int = 0,
        rotate_keep: int = 3,
        out: Callable[[bytes], object] | None = None,
        clock: Callable[[], float] = time.monotonic,
        stray_grace: float = 2.0,
        spawner: type[Process] = Process,
    ) -> None:
        if isinstance(plan, list):
            plan = Plan(steps=[Spawn(spec=s) for s in plan])
        self.screen = bytearray()
        self.printer = Printer(
            out=out or self.screen.extend,
            log_dir=log_dir,
            rotate_bytes=rotate_bytes,
            rotate_keep=rotate_keep,
        )
        self.sup = Supervisor(
            plan,
            self.printer,
            install_signals=False,
            clock=clock,
            stray_grace=stray_grace,
            spawner=spawner,
        )
        self.lines: list[tuple[str, bytes]] = []
        self._triggers: list[tuple[bytes, Callable[[str, bytes], None]]] = []
        self.sup.records.subscribe(self._saw)
        self.elapsed = 0.0
        self.timed_out = False
        self._control: Control | None = None

    def control(self) -> Control:
        """The run's runtime control, made on first use (as mlaunch.app.parts.Run does)."""
        if self._control is None:
            self._control = Control(self.sup, self.printer)
        return self._control

    def when(self, needle: bytes, action: Callable[[str, bytes], None]) -> None:
        """Run ``action(label, line)`` in the loop the first time a child prints ``needle``."""
        self._triggers.append((needle, action))

    def listen(self, listener: Callable[[str, ProcessView], object]) -> None:
        """Call ``listener("started" | "exited", process)`` from the supervisor's record stream."""

        def on_record(record: Record) -> None:
            if isinstance(record, Started):
                listener("started", record.process)
            elif isinstance(record, Exited):
                listener("exited", record.process)

        self.sup.records.subscribe(on_record)

    def _saw(self, record: Record) -> None:
        if not isinstance(record, Output):
            return
        label = record.process.label
        for line in record.data.splitlines():
            self.lines.append((label, line))
            for trigger in list(self._triggers):
                if trigger[0] in line:
                    self._triggers.remove(trigger)
                    trigger[1](label, line)

    def label(self, base: str) -> str:
        """The full label (``talker-3``) of the process named ``base`` in a launch file."""
        (label,) = [k for k in self.sup.states if k.rsplit("-", 1)[0] == base]
        return label

    def pid(self, label: str) -> int:
        return self.sup.states[label].pid

    def shutdown(self, *_: object) -> None:
        self.sup.begin_shutdown("test")

    def run(self, timeout: float = 20.0) -> int:
        def too_long() -> None:
            self.timed_out = True
            self.sup.kill_everything()

        self.sup.schedule(timeout, too_long, keeps_alive=False, cancel_on_shutdown=False)
        start = time.monotonic()
        try:
            code = self.sup.run()
        finally:
            self.elapsed = time.monotonic() - start
            self.printer.flush()
            left = proctable.marked(self.sup.run_id)
            for proc in left:
                os.kill(proc.pid, signal.SIGKILL)
            assert not left, f"processes of the run left behind: {left}"
        assert not self.timed_out, "the run did not end by itself"
        return code

    @property
    def text(self) -> str:
        return self.screen.decode("utf-8")

    def messages(self, label: str) -> list[str]:
        prefix = f"] [{label}]: "
        return [line.split(prefix, 1)[1] for line in self.text.splitlines() if prefix in line]


def gone(pid: int) -> bool:
    """The pid is dead (or a zombie nobody reaped yet)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            data = f.read()
    except OSError:
        return True
    return data[data.rfind(b")") + 2 : data.rfind(b")") + 3] in (b"Z", b"X")


def proc_state(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            data = f.read()
    except OSError:
        return "gone"
    return data[data.rfind(b")") + 2 : data.rfind(b")") + 3].decode()


SLEEPER = """
import time
print("up", flush=True)
time.sleep(60)
"""


# --- exit reporting and output ------------------------------------------------------------------


def test_clean_run_keeps_last_words_and_unterminated_line(tmp_path: Path) -> None:
    code = """
    import sys
    print("first", flush=True)
    sys.stdout.write("last words without newline")
    sys.stderr.write("err line\\n")
    """
    h = Harness([make_spec("talker", code)], log_dir=str(tmp_path))
    assert h.run() == 0
    text = h.text
    assert "[talker] first\n" in text
    assert "[talker] last words without newline\n" in text
    assert "[talker] err line\n" in text
    # The output comes before the exit report, not after.
    assert text.index("last words without newline") < text.index("process has finished cleanly")
    own = (tmp_path / "talker.log").read_text()
    assert "last words without newline\n" in own and "first\n" in own
    record = h.sup.states["talker"]
    assert record.outcome == "finished cleanly" and not record.failed
    assert record.peak_rss > 1 << 20  # wait4's rusage: a Python child uses megabytes


def test_kill_9_of_a_child_is_reported_and_nothing_is_left() -> None:
    h = Harness([make_spec("victim", SLEEPER), make_spec("bystander", "print('fine')")])
    h.when(b"up", lambda label, line: os.kill(h.pid("victim"), signal.SIGKILL))
    assert h.run() == 0  # not required: the launch goes on and ends idle
    died = [m for m in h.messages("victim") if m.startswith("process has died")]
    assert died and died[0].endswith("killed by SIGKILL")
    assert h.sup.states["victim"].state == FAILED
    assert "[bystander] fine" in h.text


def test_child_ignoring_sigint_and_sigterm_is_killed_within_its_timeouts() -> None:
    code = """
    import signal, time
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    print("up", flush=True)
    time.sleep(60)
    """
    h = Harness([make_spec("stubborn", code, sigterm=0.3, sigkill=0.3)])
    h.when(b"up", h.shutdown)
    assert h.run() == 0
    msgs = h.messages("stubborn")
    assert any("failed to terminate 0.3 s after SIGINT, escalating to SIGTERM" in m for m in msgs)
    assert any("failed to terminate 0.3 s after SIGTERM, escalating to SIGKILL" in m for m in msgs)
    assert any(m.startswith("process stopped by SIGKILL") for m in msgs)


@pytest.mark.parametrize("status", [130, 1])
def test_a_child_that_exits_on_mlaunchs_signal_is_stopped_not_dead(status: int) -> None:
    code = f"""
    import os, signal, time
    signal.signal(signal.SIGINT, lambda *_: os._exit({status}))
    print("up", flush=True)
    time.sleep(60)
    """
    h = Harness([make_spec("handler", code)])
    h.when(b"up", h.shutdown)
    assert h.run() == 0
    msgs = h.messages("handler")
    assert f"process stopped after SIGINT [pid {h.pid('handler')}, exit code {status}]" in msgs
    assert "[ERROR]" not in h.text and not any("has died" in m for m in msgs)
    assert h.sup.states["handler"].state == FINISHED
    assert h.elapsed < 5


def test_sigstopped_child_still_ends_promptly_at_shutdown() -> None:
    h = Harness([make_spec("frozen", SLEEPER, sigterm=10, sigkill=10)])

    def freeze_then_stop(label: str, line: bytes) -> None:
        pid = h.pid("frozen")
        os.kill(pid, signal.SIGSTOP)
        assert wait_until(lambda: proc_state(pid) == "T", 5)
        h.shutdown()

    h.when(b"up", freeze_then_stop)
    assert h.run() == 0
    # SIGCONT goes with SIGINT: no wait for the 10 s SIGTERM step.
    assert h.elapsed < 5
    assert not any("escalating" in m for m in h.messages("frozen"))


# --- no orphans ----------------------------------------------------------------------------------


GRANDPARENT = """
import os, subprocess, sys, time
gc = {gc!r}
env = {env}
g = subprocess.Popen([sys.executable, "-c", gc], start_new_session={setsid}, env=env)
print("gc", g.pid, flush=True)
{after}
"""

GRANDCHILD = """
import os, signal, time
{ignore}
print("gc-up", flush=True)
time.sleep(60)
"""


def grandparent(*, setsid: bool, clear_env: bool = False, ignore_term: bool = False,
                exit_at_once: bool = False) -> str:  # fmt: skip
    gc = GRANDCHILD.format(
        ignore="signal.signal(signal.SIGTERM, signal.SIG_IGN)" if ignore_term else ""
    )
    return GRANDPARENT.format(
        gc=gc,
        env="{'PATH': os.environ['PATH']}" if clear_env else "None",
        setsid=setsid,
        after="" if exit_at_once else "time.sleep(60)",
    )


@pytest.mark.parametrize(
    ("setsid", "clear_env", "ignore_term", "exit_at_once"),
    [
        (False, False, False, True),  # the leader leaves; the grandchild lingers in its group
        (True, False, False, False),  # escaped into its own session: found by the marker
        (True, True, False, True),  # escaped and without the marker: found as our descendant
        (True, False, True, False),  # escaped and ignores SIGTERM: SIGKILL after the grace
    ],
    ids=["same-group", "setsid", "setsid-no-marker", "setsid-ignores-sigterm"],
)
def test_grandchildren_are_ended(
    setsid: bool, clear_env: bool, ignore_term: bool, exit_at_once: bool
) -> None:
    code = grandparent(
        setsid=setsid, clear_env=clear_env, ignore_term=ignore_term, exit_at_once=exit_at_once
    )
    h = Harness([make_spec("parent", code, sigterm=1, sigkill=1)], stray_grace=0.3)
    grandchildren: list[int] = []

    h.when(b"gc ", lambda label, line: grandchildren.append(int(line.split()[1])))
    if not exit_at_once:
        h.when(b"gc-up", h.shutdown)
    assert h.run() == 0
    assert grandchildren, h.text
    assert gone(grandchildren[0]), f"grandchild {grandchildren[0]} survived:\n{h.text}"
    if setsid:
        assert "ending stray descendant" in h.text
    assert h.elapsed < 8


# --- restart policy ------------------------------------------------------------------------------


def test_respawn_delay_backoff_and_cap() -> None:
    policy = RespawnPolicy(mode="always", delay=0.5, backoff=2.0, max_delay=3.0)
    assert [respawn_delay(policy, n) for n in range(6)] == [0.5, 1.0, 2.0, 3.0, 3.0, 3.0]
    flat = RespawnPolicy(mode="always", delay=0.5)
    assert [respawn_delay(flat, n) for n in range(3)] == [0.5, 0.5, 0.5]
    # No delay but a backoff: the backoff still grows (from 0.1 s), or it would do nothing.
    loop = RespawnPolicy(mode="always", delay=0.0, backoff=2.0, max_delay=1.0)
    assert [respawn_delay(loop, n) for n in range(5)] == [0.0, 0.2, 0.4, 0.8, 1.0]
    assert respawn_delay(loop, 10_000) == 1.0  # no overflow in a long crash loop


def write_launch(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "test.launch.py"
    path.write_text(
        "import sys\n"
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess, Shutdown\n"
        f"PY = {PY!r}\n" + textwrap.dedent(body)
    )
    return path


def plan_from(path: Path, tmp_path: Path) -> Plan:
    from mlaunch import readers
    from mlaunch.resolve.resolver import ResolveOptions, resolve

    temp = tmp_path / "temp"
    temp.mkdir(exist_ok=True)
    return resolve(
        readers.load(str(path)),
        path=str(path),
        arguments={},
        environ=dict(os.environ),
        options=ResolveOptions(temp_dir=str(temp)),
    )


def test_crash_loop_backs_off_and_gives_up(tmp_path: Path) -> None:
    path = write_launch(
        tmp_path,
        """
        def generate_launch_description():
            return LaunchDescription([ExecuteProcess(
                cmd=[PY, '-c', 'import sys; sys.exit(1)'], name='crasher',
                respawn='on-failure', respawn_delay=0.1, respawn_max_retries=3,
                respawn_backoff=2.0, respawn_max_delay=0.3)])
        """,
    )
    h = Harness(plan_from(path, tmp_path))
    starts: list[tuple[str, tuple[str, ...]]] = []
    h.listen(lambda what, p: starts.append((p.label, p.argv)) if what == "started" else None)
    assert h.run() == 0
    msgs = h.messages(h.label("crasher"))
    restarts = [m for m in msgs if ", restart " in m]
    assert restarts == [
        "exited with status 1, restart 1/3 in 0.1 s",
        "exited with status 1, restart 2/3 in 0.2 s",
        "exited with status 1, restart 3/3 in 0.3 s",
    ]
    assert msgs[-1] == "giving up after 3 restarts (exited with status 1)"
    assert len(starts) == 4 and len(set(starts)) == 1  # same label and argv every time
    record = h.sup.states[h.label("crasher")]
    assert record.state == GAVE_UP and record.restarts == 3
    assert len(h.sup.processes) <= 2  # old instances are not kept forever


def test_backoff_starts_over_after_a_stable_run(tmp_path: Path) -> None:
    counter = tmp_path / "runs"
    code = f"""
    import pathlib, sys
    p = pathlib.Path({str(counter)!r})
    n = int(p.read_text()) + 1 if p.exists() else 1
    p.write_text(str(n))
    if n == 3:
        print("stable", flush=True)
    sys.exit(1)
    """
    offset = [0.0]
    policy = RespawnPolicy(mode="on-failure", delay=0.1, backoff=2.0, max_delay=5, max_retries=3)
    h = Harness(
        [make_spec("flaky", code, respawn=policy)], clock=lambda: time.monotonic() + offset[0]
    )

    def long_run(label: str, line: bytes) -> None:
        offset[0] += STABLE_UPTIME + 1  # as if the third run had stayed up for a while

    h.when(b"stable", long_run)
    assert h.run(timeout=40) == 0
    delays = [m.rsplit(" in ", 1)[1] for m in h.messages("flaky") if ", restart " in m]
    assert delays == ["0.1 s", "0.2 s", "0.1 s"]


@pytest.mark.parametrize(("respawn", "starts"), [("True", 3), ("'on-failure'", 1)])
def test_respawn_always_restarts_a_clean_exit_on_failure_does_not(
    tmp_path: Path, respawn: str, starts: int
) -> None:
    path = write_launch(
        tmp_path,
        f"""
        def generate_launch_description():
            return LaunchDescription([ExecuteProcess(
                cmd=[PY, '-c', 'pass'], name='job', respawn={respawn}, respawn_max_retries=2)])
        """,
    )
    h = Harness(plan_from(path, tmp_path))
    assert h.run() == 0
    started = [m for m in h.messages(h.label("job")) if m.startswith("process started")]
    assert len(started) == starts


def test_respawn_delay_is_interrupted_by_shutdown() -> None:
    policy = RespawnPolicy(mode="always", delay=30.0)
    h = Harness([make_spec("slow", "import sys; sys.exit(1)", respawn=policy)])

    def on_exit(what: str, process: object) -> None:
        if what == "exited":
            h.sup.schedule(0.0, h.shutdown)

    h.listen(on_exit)
    assert h.run() == 0
    assert h.elapsed < 5
    assert "restart 1 in 30.0 s" in h.text
    assert sum(m.startswith("process started") for m in h.messages("slow")) == 1
    assert h.sup.states["slow"].state == FAILED


@pytest.mark.parametrize(
    ("how", "child", "expected"),
    [
        ("on_exit=Shutdown()", "import sys; sys.exit(3)", 1),
        ("required=True", "import sys; sys.exit(3)", 1),
        ("required=True", "import os, signal; os.kill(os.getpid(), signal.SIGKILL)", 1),
        ("on_exit=Shutdown()", "pass", 0),
    ],
    ids=["on_exit-status-3", "required-status-3", "required-signal", "required-clean"],
)
def test_required_process_ends_the_launch_and_decides_its_status(
    tmp_path: Path, how: str, child: str, expected: int
) -> None:
    path = write_launch(
        tmp_path,
        f"""
        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[PY, '-c', 'import time; time.sleep(60)'], name='other'),
                ExecuteProcess(cmd=[PY, '-c', {child!r}], name='boss', {how}),
            ])
        """,
    )
    h = Harness(plan_from(path, tmp_path))
    assert h.run() == expected
    assert "shutting down" in h.text
    assert h.sup.states[h.label("other")].outcome.startswith("stopped")
    assert h.elapsed < 8


# --- output: floods, endless lines, garbage ------------------------------------------------------


def test_flood_arrives_complete_and_in_order() -> None:
    n = 300_000
    code = f"""
    import sys
    w = sys.stdout.buffer.write
    for start in range(0, {n}, 10_000):
        w(b"".join(b"line %d\\n" % i for i in range(start, start + 10_000)))
    """
    h = Harness([make_spec("flood", code)])
    assert h.run() == 0
    lines = [x for x in bytes(h.screen).split(b"\n") if x.startswith(b"[flood] line ")]
    assert len(lines) == n
    assert lines[0] == b"[flood] line 0" and lines[-1] == b"[flood] line %d" % (n - 1)
    assert all(int(x.rsplit(b" ", 1)[1]) == i for i, x in enumerate(lines))
    print(f"in-process flood: {n / h.elapsed:,.0f} lines/s including child start-up")


def test_ten_megabyte_line_without_newline_is_passed_in_bounded_pieces(tmp_path: Path) -> None:
    size = 10_000_000
    code = f"import sys; sys.stdout.buffer.write(b'x' * {size})"
    h = Harness([make_spec("big", code)], log_dir=str(tmp_path))
    assert h.run() == 0
    pieces = [x for x in bytes(h.screen).split(b"\n") if x.startswith(b"[big] x")]
    assert sum(len(p) - len(b"[big] ") for p in pieces) == size
    assert max(len(p) for p in pieces) <= MAX_PARTIAL + 256 * 1024 + 16
    assert (tmp_path / "big.log").stat().st_size == size + len(pieces)  # one newline per piece


def test_invalid_utf8_prints_as_replacement_characters() -> None:
    code = r"""
    import sys
    w = sys.stdout.buffer.write
    w(b"caf\xc3\xa9 ok\n")
    w(b"bad \xff\xfe end\n")
    w(b"cut \xe2\x82")
    """
    h = Harness([make_spec("garbage", code)])
    assert h.run() == 0
    text = h.text  # decodes strictly: the screen only ever gets valid UTF-8
    assert "[garbage] café ok\n" in text
    assert "[garbage] bad \ufffd\ufffd end\n" in text
    assert "[garbage] cut \ufffd\n" in text


def test_an_endless_line_is_never_cut_inside_a_character() -> None:
    code = "import sys; sys.stdout.buffer.write('é'.encode() * 200_000)"
    h = Harness([make_spec("accents", code)])
    assert h.run() == 0
    pieces = [x for x in h.text.split("\n") if x.startswith("[accents] ")]
    assert len(pieces) > 1
    assert "".join(p[len("[accents] ") :] for p in pieces) == "é" * 200_000


def test_utf8_safe_cut() -> None:
    e = "é".encode()  # 2 bytes
    euro = "€".encode()  # 3 bytes
    assert utf8_safe_cut(b"abc") == 3
    assert utf8_safe_cut(b"a" + e) == 3
    assert utf8_safe_cut(b"a" + e[:1]) == 1
    assert utf8_safe_cut(b"a" + euro[:2]) == 1
    assert utf8_safe_cut(b"a" + euro) == 4


def test_a_stuck_terminal_never_blocks_the_children(tmp_path: Path) -> None:
    r, w = os.pipe()  # a terminal nobody reads
    try:
        screen = Screen(w, limit=512 * 1024)
        n = 200_000
        code = f"""
        import sys
        sys.stdout.buffer.write(b"".join(b"line %d\\n" % i for i in range({n})))
        """
        h = Harness([make_spec("chatty", code)], out=screen, log_dir=str(tmp_path))
        assert h.run() == 0
        assert screen.dropped_lines > 0
        got = bytearray()
        os.set_blocking(r, False)

        def drained() -> bool:
            try:
                got.extend(os.read(r, 1 << 20))
            except BlockingIOError:
                pass
            screen.flush()
            return not screen.blocked and b"the terminal fell behind" in got

        assert wait_until(drained, 10)
        # mlaunch's own messages are never dropped, only the children's lines.
        assert b"[INFO] [chatty]: process has finished cleanly" in got
        # The log file has every line.
        logged = (tmp_path / "chatty.log").read_bytes().count(b"\n")
        assert logged == n
    finally:
        os.close(r)
        os.close(w)


def test_log_files_rotate_at_the_size_limit(tmp_path: Path) -> None:
    code = """
    for i in range(3000):
        print(f"log line {i:05d} " + "x" * 40, flush=True)
    """
    h = Harness(
        [make_spec("rot", code, output="log")],
        log_dir=str(tmp_path),
        rotate_bytes=20_000,
        rotate_keep=2,
    )
    assert h.run() == 0
    files = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("rot.log"))
    assert files == ["rot.log", "rot.log.1", "rot.log.2"]
    for name in files:
        assert (tmp_path / name).stat().st_size <= 20_000
    kept = b"".join((tmp_path / n).read_bytes() for n in ["rot.log.2", "rot.log.1", "rot.log"])
    numbers = [int(line.split()[2]) for line in kept.splitlines()]
    assert numbers[-1] == 2999 and numbers == list(range(numbers[0], 3000))
    # launch.log never rotates (mlaunch's own messages are never dropped); past the limit it
    # stops copying the process's lines, and says so once.
    assert not (tmp_path / "launch.log.1").exists()
    launch_log = (tmp_path / "launch.log").read_text()
    assert launch_log.count("launch.log has reached 20000 bytes") == 1
    assert "process has finished cleanly" in launch_log


def test_a_log_file_that_cannot_be_written_is_reported_once_and_the_run_goes_on(
    tmp_path: Path,
) -> None:
    if os.geteuid() == 0:  # a full disk: the device /dev/full is, made in the log folder
        os.mknod(tmp_path / "full.log", stat.S_IFCHR | 0o666, os.makedev(1, 7))
        said = "No space left on device"
    else:  # a folder it cannot write into
        tmp_path.chmod(0o500)
        said = "Permission denied"
    code = """
    for i in range(2000):
        print("line", i, flush=True)
    """
    h = Harness([make_spec("full", code)], log_dir=str(tmp_path))
    try:
        assert h.run() == 0
    finally:
        tmp_path.chmod(0o700)
    assert h.text.count("cannot write") == 1
    assert said in h.text
    assert "[full] line 1999" in h.text


def test_a_log_file_is_never_written_through_a_symlink(tmp_path: Path) -> None:
    """Someone who could put a link at a log file's name (a log folder another user could
    change) would have had a child's output appended to the file it names."""
    target = tmp_path / "elsewhere.txt"
    target.write_text("someone's file\n")
    (tmp_path / "talker.log").symlink_to(target)
    h = Harness([make_spec("talker", 'print("hello", flush=True)')], log_dir=str(tmp_path))
    assert h.run() == 0
    assert "cannot write" in h.text and "a symlink stands at its name" in h.text
    assert target.read_text() == "someone's file\n"


def test_logfile_keeps_lines_whole_across_rotation(tmp_path: Path) -> None:
    log = LogFile(str(tmp_path / "a.log"), rotate_bytes=10, keep=5)
    log.write(b"1234\n5678\nabcd\n")
    log.write(b"a line longer than the limit\n")
    log.close()
    parts = [(tmp_path / n).read_bytes() for n in ["a.log.2", "a.log.1", "a.log"]]
    assert parts == [b"1234\n5678\n", b"abcd\n", b"a line longer than the limit\n"]


# --- crashes and core dumps ---------------------------------------------------------------------


def hint_for(
    pattern: str,
    *,
    dumped: bool = True,
    uses_pid: bool = False,
    limit: int = -1,
    signal_number: int = signal.SIGSEGV,
) -> str | None:
    return core_dump_hint(
        pid=42,
        signal_number=signal_number,
        dumped=dumped,
        executable="/opt/bin/talker",
        cwd="/w",
        pattern=pattern,
        uses_pid=uses_pid,
        limit=limit,
    )


def test_core_dump_hints() -> None:
    assert hint_for("core", dumped=False, limit=0) == (
        "core dumps are off (ulimit -c is 0; 'ulimit -c unlimited' turns them on)"
    )
    assert hint_for("core", dumped=False, limit=-1) == "no core dump was written"
    assert hint_for("|/lib/systemd/systemd-coredump %P %u %g %s") == (
        "core dump kept by systemd-coredump: coredumpctl gdb 42"
    )
    assert hint_for("|/usr/share/apport/apport %p") == (
        "core dump handed to /usr/share/apport/apport"
    )
    assert hint_for("/var/crash/core.%e.%p.%t") == (
        "core dump expected at /var/crash/core.talker.42.*"
        " (gdb /opt/bin/talker /var/crash/core.talker.42.*)"
    )
    assert (hint_for("core", uses_pid=True) or "").startswith("core dump expected at /w/core.42 ")
    assert hint_for("core", dumped=False, signal_number=signal.SIGTERM) is None
    assert expand_core_pattern("%%-%e-%h", pid=1, executable="x") == f"%-x-{os.uname().nodename}"


def test_a_crash_by_signal_says_so_and_where_the_core_went(tmp_path: Path) -> None:
    pattern = Path("/proc/sys/kernel/core_pattern").read_text().strip()
    off = make_spec("off", "", argv=("/bin/sh", "-c", "ulimit -c 0; kill -SEGV $$"))
    dump = make_spec(
        "dump", "", argv=("/bin/sh", "-c", "ulimit -c unlimited; kill -SEGV $$"), cwd=str(tmp_path)
    )
    h = Harness([off, dump])
    assert h.run() == 0
    died = [m for m in h.messages("off") if m.startswith("process has died")]
    assert died[0].endswith("killed by SIGSEGV")
    hint = h.messages("off")[-1]
    if resource.getrlimit(resource.RLIMIT_CORE)[0] == 0:
        assert hint.startswith("core dumps are off")
    else:
        assert hint == "no core dump was written"
    msgs = h.messages("dump")
    if pattern.startswith("|") or "%" in pattern or "/" in pattern:
        assert any(m.startswith("core dump") for m in msgs)
        return
    assert any(m.endswith("killed by SIGSEGV (core dumped)") for m in msgs)
    expected = [m for m in msgs if m.startswith("core dump expected at ")]
    assert expected and expected[0].startswith(f"core dump expected at {tmp_path / pattern}")
    core = Path(expected[0].split(" at ", 1)[1].split(" (gdb ", 1)[0])
    assert wait_until(core.exists, 5)


def test_process_io_handlers_see_the_last_words_too(tmp_path: Path) -> None:
    path = write_launch(
        tmp_path,
        """
        from launch.actions import LogInfo, RegisterEventHandler
        from launch.event_handlers import OnProcessIO

        def generate_launch_description():
            talker = ExecuteProcess(
                cmd=[PY, '-c', 'import sys; print("one", flush=True); sys.stdout.write("last")'],
                name='talker')
            seen = lambda event: [LogInfo(msg='saw ' + event.text.decode().strip())]
            return LaunchDescription([
                RegisterEventHandler(OnProcessIO(target_action=talker, on_stdout=seen)),
                talker,
            ])
        """,
    )
    h = Harness(plan_from(path, tmp_path))
    assert h.run() == 0
    assert "saw one" in h.text
    assert "saw last" in h.text  # the unterminated line flushed at exit reaches handlers


def test_held_process_is_signalled_only_when_released() -> None:
    """hold_stop keeps a process out of the ladder (lifecycle deactivation) until release_stop."""
    code = "import sys, time; print('up', sys.argv[1], flush=True); time.sleep(30)"
    h = Harness(
        [
            make_spec("held-1", code, argv=(PY, "-c", code, "held")),
            make_spec("free-2", code, argv=(PY, "-c", code, "free")),
        ]
    )
    order: list[str] = []

    def on_shutdown_hold(*_: object) -> None:
        held = next(p for p in h.sup.processes if p.label == "held-1")
        h.sup.hold_stop(held)

        def release() -> None:
            order.append("release")
            h.sup.release_stop(held)

        h.sup.schedule(0.3, release, cancel_on_shutdown=False)

    started: set[str] = set()

    def ready(label: str, _line: bytes) -> None:
        started.add(label)
        if started == {"held-1", "free-2"}:
            on_shutdown_hold()
            h.shutdown()

    h.when(b"up held", ready)
    h.when(b"up free", ready)
    h.listen(lambda what, p: order.append(f"{what} {p.label}") if what == "exited" else None)
    h.run()
    # The free one was stopped at once; the held one only after its release.
    assert order.index("exited free-2") < order.index("release") < order.index("exited held-1"), (
        order
    )


# --- how a child is started: engine.spawning, or Popen where it is not available ------------


class PopenProcess(Process):
    """A Process started by subprocess.Popen, as on a Python whose fork_exec is unknown."""

    direct = False


def output(h: Harness, label: str) -> list[str]:
    """What the child of ``label`` wrote, line by line."""
    return [line.decode() for who, line in h.lines if who == label]


KINDS = pytest.mark.parametrize("kind", [Process, PopenProcess], ids=["direct", "popen"])


@KINDS
def test_a_program_that_cannot_start_is_said_and_the_run_goes_on(
    kind: type[Process], tmp_path: Path
) -> None:
    plain = tmp_path / "plain"
    plain.write_text("not a program\n")
    specs = [
        make_spec("missing", "", argv=("no-such-program-xyz",)),
        make_spec("plain", "", argv=(str(plain),)),
        make_spec("fine", "print('fine')"),
    ]
    h = Harness(specs, spawner=kind)
    failed: dict[str, str] = {}
    h.sup.records.subscribe(
        lambda r: failed.update({r.process.label: r.reason}) if isinstance(r, FailedToStart) else 0
    )
    assert h.run() == 0
    assert failed == {"missing": "No such file or directory", "plain": "Permission denied"}
    assert h.sup.states["missing"].state == FAILED
    assert "[fine] fine" in h.text
    assert "failed to start" in h.text or "No such file or directory" in h.text


@KINDS
def test_a_child_gets_argv_env_cwd_the_run_marker_and_a_stdin_that_stays_open(
    kind: type[Process], tmp_path: Path
) -> None:
    code = """
        import json, os, select, sys
        # stdin is a pipe nobody writes to: not readable (no EOF) while the run holds it.
        readable = select.select([sys.stdin], [], [], 0.5)[0]
        print(json.dumps({"argv": sys.argv[1:], "cwd": os.getcwd(), "stdin": bool(readable),
                          "env": {k: v for k, v in os.environ.items() if k.startswith("MLAUNCH")},
                          "mine": os.environ.get("MINE")}))
    """
    spec = make_spec("kid", code, cwd=str(tmp_path))
    spec.argv = (*spec.argv, "a b", "")
    spec.env = {**spec.env, "MINE": "x y"}
    h = Harness([spec], spawner=kind)
    assert h.run() == 0
    (line,) = output(h, "kid")
    seen = json.loads(line)
    assert seen["argv"] == ["a b", ""] and seen["cwd"] == str(tmp_path)
    assert seen["stdin"] is False, "stdin read EOF or data: it must be an open, empty pipe"
    assert seen["mine"] == "x y"
    assert any(h.sup.run_id in v for v in seen["env"].values()), seen["env"]


@KINDS
def test_shell_joins_the_command_and_emulate_tty_gives_terminals(kind: type[Process]) -> None:
    shell = make_spec("sh", "", argv=("echo", "$MINE", "two  spaces"))
    shell.shell = True
    shell.env = {**shell.env, "MINE": "expanded"}
    tty = make_spec("tty", "import os; print(os.isatty(0), os.isatty(1), os.isatty(2))")
    tty.emulate_tty = True
    h = Harness([shell, tty], spawner=kind)
    assert h.run() == 0
    assert output(h, "sh") == ["expanded two spaces"]
    assert output(h, "tty") == ["False True True"]


@KINDS
def test_only_fds_0_to_2_reach_a_child(kind: type[Process]) -> None:
    leaky_r, leaky_w = os.pipe()
    os.set_inheritable(leaky_r, True)
    try:
        code = "import os; print(sorted(os.listdir('/proc/self/fd')))"
        h = Harness([make_spec("fds", code)], spawner=kind)
        assert h.run() == 0
        # The child's own listing holds the fd of the folder it lists (3) and nothing else.
        assert output(h, "fds") == ["['0', '1', '2', '3']"]
    finally:
        os.close(leaky_r)
        os.close(leaky_w)


STARVED = """
import json, os, resource, sys
from mlaunch.engine import fdlimit
from mlaunch.engine.output import Printer
from mlaunch.engine.process import Process
from mlaunch.engine.supervisor import Supervisor
from mlaunch.plan.records import Output
from mlaunch.plan.steps import Plan, ProcessSpec, Spawn

soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
users = min(soft, 1024)  # the user's own limit here: room above it to raise
resource.setrlimit(resource.RLIMIT_NOFILE, (users, hard))
fdlimit.LIMIT = fdlimit.Limit()
attempts = []

class Starved(Process):
    direct = sys.argv[1] == "direct"

    def spawn(self, *args, **kwargs):
        if not attempts:  # the first start finds no descriptor free: no pipe fits
            resource.setrlimit(resource.RLIMIT_NOFILE, (len(os.listdir("/proc/self/fd")), hard))
        attempts.append(resource.getrlimit(resource.RLIMIT_NOFILE)[0])
        super().spawn(*args, **kwargs)

code = "import resource; print(resource.getrlimit(resource.RLIMIT_NOFILE)[0])"
spec = ProcessSpec("kid", (sys.executable, "-c", code), dict(os.environ), {}, output="screen")
screen, lines = bytearray(), []
sup = Supervisor(
    Plan(steps=[Spawn(spec=spec)]), Printer(out=screen.extend), install_signals=False,
    spawner=Starved,
)
sup.records.subscribe(lambda r: lines.append(r.data.decode()) if isinstance(r, Output) else 0)
status = sup.run()
print(json.dumps({"status": status, "attempts": attempts, "users": users, "lines": lines,
                  "screen": screen.decode()}))
"""


@pytest.mark.parametrize("kind", ["direct", "popen"])
def test_a_start_that_runs_out_of_fds_raises_the_limit_and_tries_once_more(kind: str) -> None:
    """EMFILE at a start (a handler's process in a run whose plan fit): the run's soft limit is
    raised and the start tried again; the child gets the user's own limit back. In a process of
    its own: the limit is the whole process's (an xdist worker's threads must not starve)."""
    done = subprocess.run([PY, "-c", STARVED, kind], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    seen = json.loads(done.stdout.splitlines()[-1])
    assert seen["status"] == 0, seen["screen"]
    attempts = seen["attempts"]
    assert len(attempts) == 2 and attempts[1] > attempts[0], attempts
    assert seen["lines"] == [f"{seen['users']}\n"]  # the user's own, not the raised one
    assert "Too many open files" not in seen["screen"]


@KINDS
def test_a_value_no_exec_can_take_fails_that_start_only_and_names_the_value(
    kind: type[Process],
) -> None:
    """A NUL byte in an argument or the environment, or "=" in a variable's name (both crashed
    the run with "internal error: ValueError"), is that process's failure to start."""
    nul_arg = make_spec("nul-arg", "", argv=("echo", "a\0b"))
    nul_env = make_spec("nul-env", "print('x')")
    nul_env.env = {**nul_env.env, "BAD": "x\0y"}
    eq_name = make_spec("eq-name", "print('x')")
    eq_name.env = {**eq_name.env, "A=B": "1"}
    h = Harness([nul_arg, nul_env, eq_name, make_spec("fine", "print('fine')")], spawner=kind)
    failed: dict[str, str] = {}
    h.sup.records.subscribe(
        lambda r: failed.update({r.process.label: r.reason}) if isinstance(r, FailedToStart) else 0
    )
    assert h.run() == 0
    assert failed == {
        "nul-arg": "argument 1 'a\\x00b' holds a NUL byte, which no program argument can",
        "nul-env": "environment variable BAD is 'x\\x00y': a NUL byte, which no value can hold",
        "eq-name": "environment variable name 'A=B' holds '=' or a NUL byte, which no name can",
    }
    assert "[fine] fine" in h.text and "internal error" not in h.text
