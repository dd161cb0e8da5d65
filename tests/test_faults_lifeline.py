"""Faults outside the supervisor's loop: a signal (or kill -9) while the launch file is loaded or
resolved, Ctrl-C during a long batch of spawns, closed and broken standard streams.

The windows are made long and observable on purpose: a ``Command`` substitution (or the launch
file's own code) starts a helper that writes its pid, and the run id it inherited, to a file,
then waits; the test waits for that file with a deadline, then injects the fault.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest
from procutil import wait_until
from test_faults import PY, Mlaunch, alive, assert_nothing_left

# Writes "<run id> <pid>" to argv[1], starts a grandchild in a session of its own that does the
# same to argv[1] + ".grand", then waits: what a slow xacro or a daemon-starting command is.
HELPER = (
    "import os, subprocess, sys, time\n"
    "path = sys.argv[1]\n"
    "if not path.endswith('.grand'):\n"
    "    subprocess.Popen([sys.executable, path + '.py', path + '.grand'], start_new_session=True)\n"
    "with open(path + '.tmp', 'w') as f:\n"
    "    f.write(f\"{os.environ.get('MLAUNCH_RUN_ID')} {os.getpid()}\")\n"
    "os.rename(path + '.tmp', path)\n"
    "time.sleep(60)\n"
)


def helper(tmp_path: Path, name: str) -> Path:
    """The helper's pid file (the code is beside it, for the grandchild to run)."""
    pid_file = tmp_path / name
    (tmp_path / f"{name}.py").write_text(HELPER)
    return pid_file


def read_pids(pid_file: Path) -> tuple[str, list[int]]:
    """(run id, [helper pid, grandchild pid]) once both have written their files."""
    grand = Path(f"{pid_file}.grand")
    assert wait_until(lambda: pid_file.exists() and grand.exists(), 20), "helper never started"
    run_id, pid = pid_file.read_text().split()
    grand_id, grand_pid = grand.read_text().split()
    assert run_id == grand_id != "None", "the run's marker must reach what loading starts"
    return run_id, [int(pid), int(grand_pid)]


def command_launch(tmp_path: Path, pid_file: Path) -> Path:
    """A launch whose resolving runs the helper through a Command substitution."""
    path = tmp_path / "slow_command.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "from launch.substitutions import Command\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([ExecuteProcess(\n"
        f"        cmd=['echo', Command([{PY!r}, ' ', {str(pid_file) + '.py'!r}, ' ',"
        f" {str(pid_file)!r}])], output='screen')])\n"
    )
    return path


def loading_launch(tmp_path: Path, pid_file: Path) -> Path:
    """A launch file whose own code, at load time, starts the helper and then takes its time."""
    path = tmp_path / "slow_load.launch.py"
    path.write_text(
        "import subprocess, sys, time\n"
        "from launch import LaunchDescription\n"
        f"subprocess.Popen([sys.executable, {str(pid_file) + '.py'!r}, {str(pid_file)!r}])\n"
        "def generate_launch_description():\n"
        "    time.sleep(60)\n"
        "    return LaunchDescription([])\n"
    )
    return path


# --- a signal, or kill -9, while loading or resolving ---------------------------------------------


@pytest.mark.parametrize(
    "sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT], ids=lambda s: s.name
)
@pytest.mark.parametrize("phase", ["resolving", "loading"])
def test_a_stop_signal_before_the_launch_starts(tmp_path: Path, phase: str, sig: int) -> None:
    pid_file = helper(tmp_path, "helper")
    make = command_launch if phase == "resolving" else loading_launch
    m = Mlaunch(tmp_path, make(tmp_path, pid_file))
    try:
        run_id, pids = read_pids(pid_file)
        assert len(list(m.tmp.glob("mlaunch-*"))) == 1  # the private folder exists already
        m.popen.send_signal(sig)
        assert m.wait() == 128 + sig, m.text
        err = m.stderr()
        assert f"stopped by {signal.Signals(sig).name} before the launch had started" in err, err
        assert "Traceback" not in err and "internal error" not in err, err
        # The command, and its grandchild in a session of its own, end with mlaunch.
        assert_nothing_left(run_id, pids, timeout=1)
        assert not list(m.tmp.glob("mlaunch-*")), "private folder left on disk"
    finally:
        m.close()


@pytest.mark.parametrize("phase", ["resolving", "loading"])
def test_kill_9_before_the_launch_starts_leaves_nothing(tmp_path: Path, phase: str) -> None:
    pid_file = helper(tmp_path, "helper")
    make = command_launch if phase == "resolving" else loading_launch
    m = Mlaunch(tmp_path, make(tmp_path, pid_file))
    try:
        run_id, pids = read_pids(pid_file)
        m.popen.send_signal(signal.SIGKILL)
        assert m.wait() == -signal.SIGKILL
        assert_nothing_left(run_id, pids)  # the guard, forked before loading, ends them
        assert wait_until(lambda: not list(m.tmp.glob("mlaunch-*")), 5), "private folder left"
        assert "died without stopping its processes" in m.stderr()
    finally:
        m.close()


# --- Ctrl-C during the first batch of spawns ------------------------------------------------------

BATCH = 300


def batch_launch(tmp_path: Path, killer: str, stubborn: bool) -> Path:
    """``killer`` (a shell line) first, then BATCH sleepers; each spawn takes milliseconds."""
    sleeper = "trap '' INT TERM; exec sleep 60" if stubborn else "exec sleep 60"
    timeouts = ", sigterm_timeout='30', sigkill_timeout='30'" if stubborn else ""
    path = tmp_path / "batch.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        f"    first = [ExecuteProcess(cmd=['sh', '-c', {killer!r}], name='killer'{timeouts})]\n"
        "    return LaunchDescription(first + [\n"
        f"        ExecuteProcess(cmd=['sh', '-c', {sleeper!r}], name='s'{timeouts})\n"
        f"        for _ in range({BATCH})])\n"
    )
    return path


def started(text: str) -> int:
    return text.count("process started with pid")


def test_ctrl_c_during_the_spawn_batch_acts_at_once(tmp_path: Path) -> None:
    # The first process interrupts mlaunch while the other 300 are still being started.
    m = Mlaunch(tmp_path, batch_launch(tmp_path, "kill -INT $PPID; exec sleep 60", False))
    try:
        assert m.wait(timeout=60) == 130, m.text
        n = started(m.text)
        assert n < BATCH, f"all {n} processes were started before Ctrl-C was acted on"
        assert f"{BATCH + 1 - n} processes not started: the launch is shutting down" in m.text
        assert m.text.count("not started") == 1  # one line, not one per process
    finally:
        m.close()


def test_a_second_ctrl_c_during_the_spawn_batch_kills_at_once(tmp_path: Path) -> None:
    # Everything ignores SIGINT and SIGTERM (30 s each): only the second Ctrl-C's SIGKILL ends
    # them. The killer sends both, the second once the first was acted on (the log says so).
    killer = (
        "trap '' INT TERM; kill -INT $PPID; "
        "while ! grep -qs 'user interrupted' \"$ROS_LOG_DIR\"/*/launch.log; do sleep 0.01; done; "
        "kill -INT $PPID; exec sleep 60"
    )
    m = Mlaunch(tmp_path, batch_launch(tmp_path, killer, True))
    try:
        t0 = time.monotonic()
        assert m.wait(timeout=60) == 130, m.text
        print(f"second Ctrl-C: mlaunch exited {time.monotonic() - t0:.2f} s after start")
        assert "stopping now: SIGKILL to every process" in m.text
        assert started(m.text) < BATCH + 1
        pids = [
            int(w.strip("[]")) for w in m.text.split() if w.startswith("[") and w[1:-1].isdigit()
        ]
        assert wait_until(lambda: not any(alive(p) for p in pids), 5), "a sleeper outlived mlaunch"
    finally:
        m.close()


# --- closed and broken standard streams ---------------------------------------------------------


def quick_launch(tmp_path: Path) -> Path:
    path = tmp_path / "quick.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        "        ExecuteProcess(cmd=['echo', 'hello from the child'], output='screen')])\n"
    )
    return path


def run_with_shell(tmp_path: Path, shell: str, *args: str) -> subprocess.CompletedProcess[str]:
    """``shell`` with $M the mlaunch command line (so a stream can be closed with >&-)."""
    env = dict(os.environ, TMPDIR=str(tmp_path), ROS_LOG_DIR=str(tmp_path / "log"))
    env.pop("MLAUNCH_RUN_ID", None)
    command = " ".join([PY, "-m", "mlaunch", *args])
    return subprocess.run(
        ["bash", "-c", shell.replace("$M", command)],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )


@pytest.mark.parametrize("closed", ["stdout", "stderr"])
def test_a_closed_stream_at_start(tmp_path: Path, closed: str) -> None:
    redirect = ">&-" if closed == "stdout" else "2>&-"
    result = run_with_shell(tmp_path, f"$M {redirect}; echo status=$?", str(quick_launch(tmp_path)))
    assert "status=0" in result.stdout, result.stdout + result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    if closed == "stderr":
        assert "[echo-1] hello from the child" in result.stdout
    logs = list((tmp_path / "log").glob("*/echo-1.log"))
    assert logs and "hello from the child" in logs[0].read_text()
    assert "All log files" in next((tmp_path / "log").glob("*/launch.log")).read_text()
    assert not list(tmp_path.glob("mlaunch-*"))


@pytest.mark.parametrize("view", ["--print", "--show-args"])
def test_a_reader_that_goes_away_ends_mlaunch_like_a_unix_tool(tmp_path: Path, view: str) -> None:
    # Large enough that the reader leaves long before mlaunch has written everything.
    path = tmp_path / "big.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import DeclareLaunchArgument, ExecuteProcess\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription(\n"
        "        [DeclareLaunchArgument(f'a{i}', default_value='x' * 40) for i in range(3000)]\n"
        "        + [ExecuteProcess(cmd=['echo', str(i)]) for i in range(3000)])\n"
    )
    shell = '$M | head -1; echo "status=${PIPESTATUS[0]}"'
    result = run_with_shell(tmp_path, shell, str(path), view)
    assert "status=141" in result.stdout, result.stdout + result.stderr  # as `cat`: SIGPIPE
    assert result.stderr == "", result.stderr
    assert not list(tmp_path.glob("mlaunch-*"))


# --- the marker scan --------------------------------------------------------------------------------


def test_the_marker_scan_finds_a_process_in_the_middle_of_exec() -> None:
    # While a process runs execve() its environment reads empty for a moment; a sweep that
    # looked just then used to miss a stray (setsid here is exec'ing sleep when it is scanned).
    from mlaunch.engine import guard as guards
    from mlaunch.engine import proctable

    run_id = guards.new_run_id()
    env = dict(os.environ, MLAUNCH_RUN_ID=run_id)
    missed = []
    for _ in range(60):
        sh = subprocess.Popen(
            ["/bin/sh", "-c", "setsid sleep 5 & echo $!; exit 0"], stdout=subprocess.PIPE, env=env
        )
        assert sh.stdout is not None
        pid = int(sh.stdout.readline())
        info = proctable.proc_info(pid)  # looked at first, at once: the race is in the first ms
        if info is not None and not proctable.marked(run_id, [info]):
            missed.append(pid)
        sh.wait()
        os.kill(pid, signal.SIGKILL)
    assert not missed, f"{len(missed)} of 60 marked processes were not found"


# --- nothing left without the marker: the run's cgroup, and a guard pkill -f does not match -------

# Double-forks into a session of its own, clears its environment (so the run's marker is gone),
# says its pid, and sleeps: what a daemon started by a launch file does.
DAEMON = (
    "import os, sys, time\n"
    "if os.fork():\n"
    "    time.sleep(60)\n"  # the launch's process stays up: the daemon is not an orphan of ours
    "    sys.exit(0)\n"
    "os.setsid()\n"
    "if os.fork():\n"
    "    os._exit(0)\n"
    "with open(sys.argv[1] + '.tmp', 'w') as f:\n"
    "    f.write(str(os.getpid()))\n"
    "os.rename(sys.argv[1] + '.tmp', sys.argv[1])\n"
    "os.execve('/bin/sleep', ['sleep', '60'], {})\n"
)


def run_cgroup_available() -> str:
    """Why this machine gives a run no cgroup ("" when it does), asked as mlaunch asks."""
    code = (
        "import os\n"
        "from mlaunch.engine.cgroup import RunCgroup\n"
        "group, why = RunCgroup.create(os.environ)\n"
        "if group is not None:\n"
        "    why = '' if group.enter() else f'cannot move into {group.path}'\n"
        "    group.leave()\n"
        "print(why)\n"
    )
    done = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@pytest.mark.skipif(shutil.which("pkill") is None, reason="needs pkill(1) from procps")
def test_pkill_9_f_of_mlaunch_leaves_nothing_not_even_a_daemon(tmp_path: Path) -> None:
    from test_faults import SLEEPER, proc, write_launch

    daemon_pid = tmp_path / "daemon.pid"
    launch = write_launch(
        tmp_path,
        [
            proc(SLEEPER, "plain", sigkill_timeout=0.5),
            "ExecuteProcess(cmd=[PY, '-c', "
            f"{DAEMON!r}, {str(daemon_pid)!r}], name='daemonizer', sigkill_timeout=0.5)",
        ],
    )
    no_cgroup = run_cgroup_available()
    m = Mlaunch(tmp_path, launch)
    try:
        run_id, pid = m.wait_ups(1)[0]
        assert wait_until(daemon_pid.exists, 15), m.text
        daemon = int(daemon_pid.read_text())
        # What `pkill -9 -f mlaunch` does, narrowed to this run's command line: it must not
        # match the guard, which then ends the run.
        subprocess.run(["pkill", "-9", "-f", str(launch)], check=True, timeout=10)
        assert m.wait() == -signal.SIGKILL
        assert_nothing_left(run_id, [pid])
        assert wait_until(lambda: not list(m.tmp.glob("mlaunch-*")), 5), "private folder left"
        err = m.stderr()
        assert "died without stopping its processes" in err, err
        if no_cgroup:
            os.kill(daemon, signal.SIGKILL)
            pytest.skip(
                f"the daemon that cleared its environment needs the run's cgroup: {no_cgroup}"
            )
        assert wait_until(lambda: not alive(daemon), 10), "the daemon outlived the run"
        assert "the run had no cgroup" not in err
    finally:
        m.close()


def test_the_guard_is_not_named_after_mlaunch() -> None:
    from mlaunch.engine.guard import Guard

    guard = Guard.start("probe-title")
    try:
        path = Path(f"/proc/{guard.pid}/cmdline")
        assert wait_until(lambda: path.read_bytes().startswith(b"launch-guard"), 5)
        cmdline = path.read_bytes().rstrip(b"\0").decode()
        assert cmdline == f"launch-guard [run {os.getpid()}]"[: len(cmdline)]
        assert "mlaunch" not in cmdline
        assert Path(f"/proc/{guard.pid}/comm").read_text().strip() == "launch-guard [r"
    finally:
        guard.close()


def test_a_normal_run_leaves_no_cgroup_behind(tmp_path: Path) -> None:
    from mlaunch.engine.cgroup import PREFIX, cgroup2_root, own_cgroup

    if run_cgroup_available():
        pytest.skip(f"no run cgroup here: {run_cgroup_available()}")
    root, mine = cgroup2_root(), own_cgroup()
    assert root is not None and mine is not None
    parent = Path(root) / mine.lstrip("/")
    m = Mlaunch(tmp_path, quick_launch(tmp_path))
    try:
        assert m.wait() == 0, m.text
        # Removed before mlaunch exits (others there belong to other runs, still running).
        ours = {p.name for p in parent.glob(f"{PREFIX}{m.popen.pid}-*")}
        assert not ours, ours
    finally:
        m.close()


SLOW_MOVE = """
import os, sys
from mlaunch.engine import cgroup
from mlaunch.engine.lifeline import Lifeline

r, w = os.pipe()
write, held = cgroup._write, []

def slow_write(path, text):
    # The first move into the run's cgroup waits until the main thread lets it go: the kernel's
    # RCU wait, made as long as the test needs.
    if path.endswith("cgroup.procs") and not held:
        held.append(path)
        os.read(r, 1)
    return write(path, text)

cgroup._write = slow_write
with Lifeline() as life:
    # The program goes on while the move waits (it cannot be done before the write below).
    moving = life.cgroup is not None and not life.cgroup.entered
    print("ENTERED", moving and not life.cgroup.path.endswith(cgroup.own_cgroup()), flush=True)
    os.write(w, b"x")
    life.settle()
    inside = cgroup.own_cgroup() or ""
    print("SETTLED", life.cgroup is not None and life.cgroup.path.endswith(inside), flush=True)
print("LEFT", cgroup.own_cgroup() != inside, flush=True)
"""


def test_mlaunch_goes_on_while_the_move_into_its_cgroup_waits() -> None:
    """Writing cgroup.procs waits for an RCU grace period (2-15 ms of wall time before the
    first child): a thread makes the move while the launch file loads; the supervisor starts
    nothing before it is done. Before, the launch waited for it."""
    if run_cgroup_available():
        pytest.skip(f"no run cgroup here: {run_cgroup_available()}")
    done = subprocess.run([PY, "-c", SLOW_MOVE], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["ENTERED", "True", "SETTLED", "True", "LEFT", "True"]
