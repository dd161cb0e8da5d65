"""A part's failure is contained (mlaunch.engine.reactor): said in one line, the part detached,
the run goes on; a part the run cannot go on without ends it through the stop ladder.

Real runs of a Supervisor with real children, as in test_supervision.
"""

from __future__ import annotations

import os
import re
import selectors
import subprocess
import sys
from pathlib import Path

from procutil import clean_env
from test_supervision import Harness, make_spec

from mlaunch.engine.part import Part
from mlaunch.engine.supervisor import Supervisor
from mlaunch.plan.errors import EXIT_INTERNAL, EXIT_OK
from mlaunch.plan.records import Exited, Output, Record, Started

# Says it is up, then ends by itself a moment later (the run then ends as idle).
BRIEF = 'import time; print("up", flush=True); time.sleep(0.5)'
# Says it is up, then exits 130 on SIGINT (what the stop ladder sends first).
WAITER = """
import os, signal, time
signal.signal(signal.SIGINT, lambda *_: os._exit(130))
print("up", flush=True)
time.sleep(60)
"""


class Recorder(Part):
    """A well-behaved part: notes every record it is handed."""

    def __init__(self, supervisor: Supervisor) -> None:
        self.seen: list[Record] = []
        self.closed = False
        supervisor.records.subscribe(self.seen.append)

    def close(self) -> None:
        self.closed = True


class Faulty(Part):
    """Raises at the first record of ``kind`` (Started, Output ...) it is handed."""

    def __init__(self, supervisor: Supervisor, kind: type[Record]) -> None:
        self.kind = kind
        self.calls = 0
        self.closed = False
        supervisor.records.subscribe(self.on_record)

    def on_record(self, record: Record) -> None:
        self.calls += 1
        if isinstance(record, self.kind):
            raise RuntimeError(f"broken at {type(record).__name__}")

    def close(self) -> None:
        self.closed = True


def error_lines(h: Harness) -> list[str]:
    return [line for line in h.text.splitlines() if line.startswith("[ERROR]")]


def test_a_subscriber_that_raises_is_said_detached_and_the_run_goes_on() -> None:
    h = Harness([make_spec("worker", BRIEF)])
    faulty = h.sup.reactor.attach("the faulty part", lambda: Faulty(h.sup, Started))
    after = h.sup.reactor.attach("the recorder", lambda: Recorder(h.sup))
    assert isinstance(faulty, Faulty) and isinstance(after, Recorder)
    code = h.run()
    assert h.sup.reactor.parts() == [after]
    h.sup.reactor.close_all()

    assert code == EXIT_OK
    assert error_lines(h) == [
        "[ERROR] [launch]: the faulty part failed and was detached: RuntimeError: broken at Started"
    ]
    assert faulty.calls == 1 and faulty.closed  # never called again, closed at once
    assert faulty.on_record not in h.sup.records.subscribers
    # The part after it still got the record the faulty one broke at, and everything after.
    kinds = [type(e) for e in after.seen]
    assert Started in kinds and Output in kinds and Exited in kinds
    assert after.closed
    assert any(m.startswith("process has finished cleanly") for m in h.messages("worker"))


class TimerAndPipe(Part):
    """Watches a pipe in the loop's selector and fails in a timer of its own."""

    def __init__(self, supervisor: Supervisor) -> None:
        self.selector = supervisor.selector
        self.read, self.write = os.pipe()
        self.readable = 0
        self.watched_at_close: bool | None = None
        self.selector.register(self.read, selectors.EVENT_READ, self.on_readable)
        supervisor.schedule(0.2, self.fail, keeps_alive=False)

    def on_readable(self, fd: int) -> None:
        self.readable += 1

    def fail(self) -> None:
        raise ValueError("timer went wrong")

    def close(self) -> None:
        self.watched_at_close = any(k.fd == self.read for k in self.selector.get_map().values())
        os.close(self.read)
        os.close(self.write)


def test_a_timer_that_raises_detaches_its_part_and_its_files() -> None:
    h = Harness([make_spec("worker", BRIEF)])
    part = h.sup.reactor.attach("the pipe watcher", lambda: TimerAndPipe(h.sup))
    assert isinstance(part, TimerAndPipe)
    assert any(k.fd == part.read for k in h.sup.selector.get_map().values())
    code = h.run()

    assert code == EXIT_OK
    assert error_lines(h) == [
        "[ERROR] [launch]: the pipe watcher failed and was detached: ValueError: timer went wrong"
    ]
    assert h.sup.reactor.parts() == []
    # Its pipe left the selector before its close() (a closed fd left in it would break the loop).
    assert part.watched_at_close is False


def test_a_part_that_fails_to_attach_is_said_and_the_run_goes_on() -> None:
    h = Harness([make_spec("worker", BRIEF)])

    def make() -> Part:
        raise OSError(13, "Permission denied")

    assert h.sup.reactor.attach("the control socket", make) is None
    assert h.run() == EXIT_OK
    assert error_lines(h) == [
        "[ERROR] [launch]: the control socket failed and was detached:"
        " PermissionError: [Errno 13] Permission denied"
    ]


def test_an_essential_part_that_fails_ends_the_run_through_the_stop_ladder() -> None:
    h = Harness([make_spec("waiter", WAITER, sigterm=5.0, sigkill=5.0)])
    h.sup.reactor.attach("the smoke checks", lambda: Faulty(h.sup, Output), essential=True)
    code = h.run()

    assert code == EXIT_INTERNAL
    assert error_lines(h)[0] == (
        "[ERROR] [launch]: the smoke checks failed and was detached: RuntimeError: broken at"
        " Output; the run cannot go on without it"
    )
    # SIGINT first, as every shutdown: the child's handler exits, nothing is killed.
    pid = h.pid("waiter")
    assert f"process stopped after SIGINT [pid {pid}, exit code 130]" in h.messages("waiter")
    assert "SIGKILL" not in h.text and "SIGTERM" not in h.text


def test_a_close_that_raises_is_said_and_the_others_still_close() -> None:
    h = Harness([make_spec("worker", BRIEF)])

    class BadClose(Recorder):
        def close(self) -> None:
            raise KeyError("gone")

    h.sup.reactor.attach("the status view", lambda: BadClose(h.sup))
    last = h.sup.reactor.attach("the exit summary", lambda: Recorder(h.sup))
    assert h.run() == EXIT_OK
    h.sup.reactor.close_all()
    h.printer.flush()
    assert error_lines(h) == [
        "[ERROR] [launch]: the status view failed and was detached: KeyError: 'gone'"
    ]
    assert isinstance(last, Recorder) and last.closed


# --- through the pipeline, as mlaunch FILE runs (a subprocess: signals, guard, log folder) ---

PIPELINE_RUN = """
import sys
from mlaunch import compat
from mlaunch.app import pipeline
from mlaunch.app.parts import PartMaker, standard_parts
from mlaunch.app.options import parse_options
from mlaunch.engine.part import Part
from mlaunch.plan.records import Started

class Broken(Part):
    def __init__(self, run):
        run.supervisor.records.subscribe(self.on_record)

    def on_record(self, event):
        if isinstance(event, Started):
            raise RuntimeError("broken at its first start")

    def close(self):
        print("BROKEN CLOSED", flush=True)

compat.install()  # as mlaunch's main does: the launch file imports the ROS 2 names
opts = parse_options([sys.argv[1]])
essential = sys.argv[2] == "essential"
extra = PartMaker("the broken part", Broken, essential=essential)
sys.exit(pipeline.launch(opts, [*standard_parts(opts), extra]))
"""


def pipeline_run(tmp_path: Path, code: str, how: str) -> subprocess.CompletedProcess[str]:
    launch = tmp_path / "one.launch.py"
    launch.write_text(
        "import sys\n"
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        f"    return LaunchDescription([ExecuteProcess(cmd=[sys.executable, '-c', {code!r}],"
        " name='worker', output='screen')])\n"
    )
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
    return subprocess.run(
        [sys.executable, "-c", PIPELINE_RUN, str(launch), how],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )


def test_a_failing_part_in_a_pipeline_run_is_said_and_the_run_goes_on(tmp_path: Path) -> None:
    done = pipeline_run(tmp_path, BRIEF, "contained")
    assert done.returncode == EXIT_OK, done.stdout + done.stderr
    said = [line for line in done.stdout.splitlines() if line.startswith("[ERROR]")]
    assert said == [
        "[ERROR] [launch]: the broken part failed and was detached:"
        " RuntimeError: broken at its first start"
    ]
    assert "BROKEN CLOSED" in done.stdout
    assert "[INFO] [worker-1]: process has finished cleanly" in done.stdout


def test_an_essential_part_failing_in_a_pipeline_run_ends_it_with_70(tmp_path: Path) -> None:
    done = pipeline_run(tmp_path, WAITER, "essential")
    assert done.returncode == EXIT_INTERNAL, done.stdout + done.stderr
    assert "the run cannot go on without it" in done.stdout
    # The ladder's first step: SIGINT (the part broke at the start, maybe before the child's
    # handler was in: then SIGINT itself ended it); nothing was killed.
    assert re.search(r"\[worker-1\]: process stopped (by|after) SIGINT \[pid \d+", done.stdout)
    assert "SIGKILL" not in done.stdout and "SIGTERM" not in done.stdout
