"""Output faults: one child flooding a slow but steady terminal, and logs that outgrow their
limits.

The terminal is a real pipe read by a thread at a fixed pace (the slow terminal); each line of
the quiet child carries the monotonic time it was printed, and the reader stamps the time each
chunk arrived, so the delay of every quiet line is measured, not guessed.
"""

from __future__ import annotations

import os
import selectors
import threading
import time
from pathlib import Path

import pytest
from test_output_flow import deadline_sleep, flood_code
from test_supervision import Harness, make_spec

from mlaunch.engine.screen import Screen

QUIET = """
import sys, time
for i in range(40):
    print(f"q {i} {time.monotonic():.6f}", flush=True)
    time.sleep(0.03)
"""


class PacedReader(threading.Thread):
    """Takes ``chunk`` bytes every ``every`` seconds, and notes when each line arrived."""

    def __init__(self, fd: int, chunk: int, every: float) -> None:
        super().__init__(daemon=True)
        self.fd, self.chunk, self.every = fd, chunk, every
        self.arrivals: list[tuple[float, bytes]] = []
        self._partial = b""

    def run(self) -> None:
        sel = selectors.DefaultSelector()
        sel.register(self.fd, selectors.EVENT_READ)
        while True:
            sel.select()
            try:
                got = os.read(self.fd, self.chunk)
            except OSError:
                return
            if not got:
                return
            now = time.monotonic()
            *lines, self._partial = (self._partial + got).split(b"\n")
            self.arrivals.extend((now, line) for line in lines)
            deadline_sleep(now + self.every)


def bytes_ahead(arrivals: list[tuple[float, bytes]], i: int, written: float) -> int:
    """The bytes of the lines that reached the reader after line ``i`` was written (the
    writer's monotonic time ``written``) and before it: the backlog it waited behind."""
    return sum(len(line) + 1 for when, line in arrivals[:i] if when >= written)


@pytest.mark.serial  # a quiet line's lag, in seconds
def test_a_flooding_child_does_not_stall_a_quiet_ones_lines() -> None:
    # ~320 KB/s: the flood (~1.5 MB) takes seconds to pass; a whole 1 MiB backlog ahead of a
    # quiet line would hold it ~3 s. Per-process flow control keeps the flood's share of it
    # near 32 KiB, ~0.1 s (the pipes hold the rest).
    r, w = os.pipe()
    screen = Screen(w)
    reader = PacedReader(r, 16 * 1024, 0.05)
    reader.start()
    specs = [make_spec("flood", flood_code(100_000, "f")), make_spec("quiet", QUIET)]
    h = Harness(specs, out=screen)
    try:
        assert h.run(timeout=60) == 0
        screen.close(timeout=30)
    finally:
        os.close(w)
        reader.join(30)
        os.close(r)
    delays, ahead = [], []
    flood_lines = 0
    for i, (arrived, line) in enumerate(reader.arrivals):
        if line.startswith(b"[quiet] q "):
            _, _, _, stamp = line.split()
            delays.append(arrived - float(stamp))
            ahead.append(bytes_ahead(reader.arrivals, i, float(stamp)))
        elif line.startswith(b"[flood] f "):
            flood_lines += 1
    assert flood_lines == 100_000, "the flood lost lines"
    assert len(delays) == 40, "the quiet child lost lines"
    worst = max(delays)
    print(
        f"quiet child's lines behind a flood: worst {worst:.3f} s, median "
        f"{sorted(delays)[20]:.3f} s; at most {max(ahead)} bytes reached the screen ahead of one"
    )
    # Flow control bounds the bytes ahead of a quiet line (how long they take also depends on
    # how busy the machine is): ~80 KB measured, the pipes and the flood's share; ~1 MiB without.
    assert max(ahead) < 256 * 1024, f"{max(ahead)} bytes reached the screen ahead of a quiet line"


# --- log retention ----------------------------------------------------------------------------------

# 3,000 numbered lines (~33 KB) to stdout, which output='log' sends to its log and launch.log.
WRITER = "import sys\nfor i in range(3000):\n    sys.stdout.write(f'line {i:05d}\\n')\n"


def run_writer(tmp_path: Path, *options: str) -> Path:
    """Run the writer through the command line with ``options``; its run's log folder."""
    from test_faults import Mlaunch, proc, write_launch

    launch = write_launch(tmp_path, [proc(WRITER, "writer").replace("'screen'", "'log'")])
    m = Mlaunch(tmp_path, launch, *options)
    try:
        assert m.wait() == 0, m.text + m.stderr()
    finally:
        m.close()
    (folder,) = [p for p in (tmp_path / "log").iterdir() if not p.is_symlink()]
    return folder


def kept_lines(folder: Path, name: str) -> list[int]:
    """The writer's line numbers in every part of ``name``, oldest part first."""
    parts = sorted(folder.glob(f"{name}.*"), key=lambda p: -int(p.suffix[1:]))
    numbers = []
    for part in [*parts, folder / name]:
        numbers += [int(line.split()[-1]) for line in part.read_text().splitlines()]
    return numbers


def test_logs_keep_what_the_options_say_and_every_message_of_mlaunch(tmp_path: Path) -> None:
    folder = run_writer(tmp_path, "--log-max-bytes", "4000", "--log-keep", "2")
    assert sorted(p.name for p in folder.glob("writer-1.log*")) == [
        "writer-1.log",
        "writer-1.log.1",
        "writer-1.log.2",
    ]
    kept = kept_lines(folder, "writer-1.log")
    assert kept == list(range(3000 - len(kept), 3000)), "the newest lines, whole and in order"
    assert len(kept) < 3000
    launch_log = (folder / "launch.log").read_text()
    assert not list(folder.glob("launch.log.*")), "launch.log never rotates"
    # mlaunch's own messages, first to last, are all there, though the process's were capped.
    assert "All log files can be found below" in launch_log.splitlines()[0]
    assert "process started with pid" in launch_log
    assert "process has finished cleanly" in launch_log.splitlines()[-1]
    assert launch_log.count("launch.log has reached 4000 bytes") == 1
    assert len(launch_log) < 4000 + 1500


def test_log_keep_all_drops_nothing(tmp_path: Path) -> None:
    folder = run_writer(tmp_path, "--log-max-bytes", "4000", "--log-keep", "all")
    assert len(list(folder.glob("writer-1.log.*"))) >= 7
    assert kept_lines(folder, "writer-1.log") == list(range(3000))


def test_a_bad_log_keep_is_one_line(tmp_path: Path) -> None:
    from procutil import clean_env, run_mlaunch

    launch = tmp_path / "x.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "def generate_launch_description():\n    return LaunchDescription([])\n"
    )
    done = run_mlaunch(str(launch), "--log-keep", "some", env=clean_env())
    assert done.returncode == 2
    assert (
        "--log-keep is 'some'; valid: a number of rotated files (0 or more), or all" in done.stderr
    )


def test_a_reader_that_leaves_during_a_run_costs_the_screen_only(tmp_path: Path) -> None:
    # `mlaunch FILE | less`, then the pager is quit: the run goes on with its log files, and
    # Ctrl-C still ends it in order (exit 130), with no BrokenPipeError anywhere.
    import signal
    import subprocess

    from test_faults import PY, proc, wait_until, write_launch

    ticker = (
        "import time\nfor i in range(100000):\n    print(f'tick {i}', flush=True)\n"
        "    time.sleep(0.005)\n"
    )
    launch = write_launch(tmp_path, [proc(ticker, "ticker")])
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / "log"), TMPDIR=str(tmp_path))
    env.pop("MLAUNCH_RUN_ID", None)
    popen = subprocess.Popen(
        [PY, "-m", "mlaunch", str(launch)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env
    )
    try:
        assert popen.stdout is not None and popen.stderr is not None
        while b"tick 3" not in popen.stdout.readline():
            pass
        popen.stdout.close()  # the pager is quit
        logs = tmp_path / "log"
        own = lambda: list(logs.glob("*/ticker-1.log"))  # noqa: E731
        assert wait_until(lambda: bool(own()) and b"tick 400" in own()[0].read_bytes(), 20)
        popen.send_signal(signal.SIGINT)
        assert popen.wait(20) == 130
        err = popen.stderr.read().decode()
        assert "Traceback" not in err and "BrokenPipe" not in err, err
        assert "process stopped by SIGINT" in next(logs.glob("*/launch.log")).read_text()
    finally:
        if popen.poll() is None:
            popen.kill()
            popen.wait()


def test_a_process_name_with_a_slash_or_dots_keeps_its_log_inside_the_log_folder(
    tmp_path: Path,
) -> None:
    # Issue 38, item 15: the name is the launch file's; `../../x` put x-1.log two folders up.
    from test_faults import Mlaunch, proc, write_launch

    names = ["../../escaped", "sub/dir", "..", "a%2Fb"]
    entries = [proc(f"print({n!r})", n).replace("'screen'", "'log'") for n in names]
    m = Mlaunch(tmp_path, write_launch(tmp_path, entries))
    try:
        assert m.wait() == 0, m.text + m.stderr()
    finally:
        m.close()
    (folder,) = [p for p in (tmp_path / "log").iterdir() if not p.is_symlink()]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["faults.launch.py", "log", "tmp"]
    assert sorted(p.name for p in (tmp_path / "log").iterdir()) == sorted(["latest", folder.name])
    files = {
        "..%2F..%2Fescaped-1.log": "../../escaped",
        "sub%2Fdir-2.log": "sub/dir",
        "..-3.log": "..",
        "a%252Fb-4.log": "a%2Fb",  # not the file of a process named a/b
    }
    assert sorted(p.name for p in folder.iterdir()) == sorted([*files, "launch.log"])
    for file, name in files.items():
        assert (folder / file).read_text() == name + "\n"
