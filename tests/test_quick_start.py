"""The quick start (mlaunch.app.quick): a repeated ``mlaunch FILE`` starts its first processes
before the rest of mlaunch is imported, and the run adopts them as if it had started them.

Every test has a cache folder of its own (XDG_CACHE_HOME) and a log folder of its own
(ROS_LOG_DIR), where launch.log says which processes were adopted. An entry is written only for
files settled for two seconds (mlaunch.plan.inputs.RACY_NS): the tests wait for that on the
file's change time, not on a sleep.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from procutil import clean_env, install_package, mlaunch, run_mlaunch, wait_until

from mlaunch.app import quick
from mlaunch.plan.inputs import RACY_NS

sys.path.insert(0, str(Path(__file__).resolve().parent / "conformance"))
import harness

LAUNCH = """\
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo

def generate_launch_description():
    return LaunchDescription([
        LogInfo(msg="{note}"),
        ExecuteProcess(cmd=["sh", "-c", 'env > "$0/env.$$"; echo "argv $*" > "$0/argv.$$"',
                            "{out}", "a b", "c"], output="screen"),
        ExecuteProcess(cmd="echo second from {note}", shell=True, output="screen"),
    ])
"""


def settled(*paths: Path) -> None:
    """Wait until every file's change time is older than the racy window."""

    def old() -> bool:
        return all(p.stat().st_ctime_ns < time.time_ns() - RACY_NS - 50_000_000 for p in paths)

    assert wait_until(old, timeout=10, interval=0.05)


@pytest.fixture
def case(tmp_path: Path) -> tuple[Path, dict[str, str], Path]:
    out = tmp_path / "out"
    out.mkdir()
    path = tmp_path / "first.launch.py"
    path.write_text(LAUNCH.format(note="one", out=out))
    env = clean_env(XDG_CACHE_HOME=str(tmp_path / "cache"), ROS_LOG_DIR=str(tmp_path / "log"))
    env.pop("MLAUNCH_NO_CACHE", None)
    settled(path, tmp_path)
    return path, env, out


def run(path: Path, env: dict[str, str], out: Path) -> tuple[str, list[str], dict[str, str]]:
    """One run: (its output, the labels launch.log says the quick start started, the first
    child's environment)."""
    logs = Path(env["ROS_LOG_DIR"])
    before = run_logs(logs)
    done = run_mlaunch(str(path), env=env, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    (log_dir,) = run_logs(logs) - before
    adopted = [
        line.split("[launch]: ")[1].split(" (pid ")[0]
        for line in (log_dir / "launch.log").read_text().splitlines()
        if line.endswith(" was started by the quick start, before mlaunch loaded its plan; adopted")
    ]
    (env_file,) = out.glob("env.*")
    (argv_file,) = out.glob("argv.*")
    child_env = dict(
        line.split("=", 1) for line in env_file.read_text().splitlines() if "=" in line
    )
    assert argv_file.read_text() == "argv a b c\n"
    env_file.unlink()
    argv_file.unlink()
    return done.stdout, adopted, child_env


def run_logs(logs: Path) -> set[Path]:
    """The runs' log folders (not the ``latest`` link)."""
    return {p for p in logs.iterdir() if not p.is_symlink()} if logs.is_dir() else set()


def entries(env: dict[str, str]) -> list[Path]:
    return sorted((Path(env["XDG_CACHE_HOME"]) / "mlaunch" / "plans").glob("*" + quick.SUFFIX))


def test_a_repeated_start_adopts_what_it_started(case: tuple[Path, dict[str, str], Path]) -> None:
    path, env, out = case
    first, adopted, env1 = run(path, env, out)
    assert adopted == []  # resolved: the entry is written now
    (entry,) = entries(env)
    assert entry.stat().st_mode & 0o777 == 0o600
    second, adopted, env2 = run(path, env, out)
    assert adopted == ["sh-1", "echo second from one-2"]
    # The same run as the resolved one: its lines, its children's argv and environment (the
    # run's own marker and log folder aside).
    for output in (first, second):
        assert "second from one" in output and "[INFO] [launch.user]: one" in output
    for name in ("MLAUNCH_RUN_ID",):
        assert env1.pop(name) != env2.pop(name)
    assert env1 == env2


def test_a_changed_file_is_resolved_again(case: tuple[Path, dict[str, str], Path]) -> None:
    path, env, out = case
    run(path, env, out)
    assert entries(env)
    mtime = path.stat().st_mtime_ns
    path.write_text(LAUNCH.format(note="two", out=out))
    os.utime(path, ns=(mtime, mtime))  # the same size and modification time: the change time tells
    output, adopted, _ = run(path, env, out)
    assert adopted == [] and "second from two" in output


def test_options_and_no_cache_are_never_quick(tmp_path: Path) -> None:
    env = {"HOME": str(tmp_path)}
    assert quick.eligible(["a.launch.py", "x:=1"], env)
    assert not quick.eligible(["a.launch.py", "--print"], env)
    assert not quick.eligible(["a.launch.py"], {**env, "MLAUNCH_NO_CACHE": "1"})
    assert not quick.eligible(["a.launch.py"], {**env, "_ARGCOMPLETE": "1"})
    assert not quick.eligible([], env)
    # The run's marker and the order of LD_LIBRARY_PATH's entries are not in the key; the
    # rest of the environment and the command line are.
    base = {**env, "LD_LIBRARY_PATH": "/a:/b"}
    assert quick.key(["f"], base) == quick.key(
        ["f"], {**base, "LD_LIBRARY_PATH": "/b:/a", "MLAUNCH_RUN_ID": "1-x"}
    )
    assert quick.key(["f"], base) != quick.key(["f", "x:=1"], base)
    assert quick.key(["f"], base) != quick.key(["f"], {**base, "ROS_DOMAIN_ID": "3"})


def test_a_child_its_plan_no_longer_starts_is_ended(tmp_path: Path) -> None:
    from mlaunch.engine.spawning import start
    from mlaunch.plan.steps import ProcessSpec

    env = {"PATH": os.environ["PATH"]}
    child = quick._start(start, "sleep-1", ("sleep", "30"), env, None, time.monotonic)
    assert child is not None
    starting = quick.QuickStart(["f"], {"HOME": str(tmp_path)})
    starting.children["sleep-1"] = child
    other = ProcessSpec(label="sleep-1", argv=("sleep", "31"), env=env, env_changes={})
    assert starting.take(other, {}) is None
    with pytest.raises(ProcessLookupError):
        os.kill(child.pid, 0)  # ended and reaped


def test_mlaunch_killed_after_a_quick_start_leaves_nothing(tmp_path: Path) -> None:
    pids = tmp_path / "pids"
    pids.mkdir()
    path = tmp_path / "long.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([ExecuteProcess(cmd=['sh', '-c',"
        f" 'echo $$ > {pids}/.tmp.$$; mv {pids}/.tmp.$$ {pids}/pid.$$; exec sleep 60'])])\n"
    )
    env = clean_env(XDG_CACHE_HOME=str(tmp_path / "cache"), ROS_LOG_DIR=str(tmp_path / "log"))
    env.pop("MLAUNCH_NO_CACHE", None)
    settled(path, tmp_path)
    for attempt in range(2):  # the first run writes the entry, the second starts quick
        proc = subprocess.Popen(
            mlaunch(str(path)), env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
        )
        assert wait_until(lambda: any(pids.glob("pid.*")), timeout=30)  # written, then renamed
        (pid_file,) = pids.glob("pid.*")
        pid = int(pid_file.read_text())
        pid_file.unlink()
        if attempt == 0:
            proc.send_signal(signal.SIGINT)
            assert proc.wait(30) == 128 + signal.SIGINT
            continue
        assert entries(env)

        # The child runs before the run has made its log folder: looked for again each time.
        def adopted() -> bool:
            logs = [p / "launch.log" for p in run_logs(tmp_path / "log")]
            return any("by the quick start" in p.read_text() for p in logs if p.exists())

        assert wait_until(adopted, timeout=30)
        proc.kill()  # SIGKILL: only the guard is left to end the child
        proc.wait(30)

        def gone(pid: int = pid) -> bool:
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                return True
            return False

        assert wait_until(gone, timeout=30), f"pid {pid} outlived mlaunch"


def test_a_resolved_run_starts_its_first_processes_before_the_supervisor(
    case: tuple[Path, dict[str, str], Path],
) -> None:
    path, env, _out = case
    env["MLAUNCH_NO_CACHE"] = "1"
    logs = Path(env["ROS_LOG_DIR"])
    done = run_mlaunch(str(path), env=env, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    (log_dir,) = run_logs(logs)
    text = (log_dir / "launch.log").read_text()
    assert text.count("was started as soon as its plan was known; adopted") == 2
    assert "quick start" not in text and not entries(env)
    assert "second from one" in done.stdout


def test_what_the_supervisor_must_start_itself_is_left_to_it(tmp_path: Path) -> None:
    from mlaunch.plan.steps import COMPONENTS, EmitEvent, Plan, ProcessSpec, Spawn

    def spec(label: str, **more: object) -> ProcessSpec:
        fields: dict[str, object] = {"argv": ("true",), **more}
        return ProcessSpec(label=label, env={}, env_changes={}, **fields)  # type: ignore[arg-type]

    plain = Plan(
        [Spawn(spec=spec("a")), Spawn(spec=spec("b", emulate_tty=True)), Spawn(spec=spec("c"))]
    )
    first, why = quick._first_processes(plain, "1-x")
    assert [f[0] for f in first] == ["a"] and "terminal" in why
    assert first[0][2] == {"MLAUNCH_RUN_ID": "1-x"}  # the run's marker, as the supervisor adds it
    # A participant must exist before the first child of a launch with composable nodes.
    components = Plan([Spawn(spec=spec("a"))], needs=set(COMPONENTS))
    assert quick._first_processes(components, "1") == ([], "the launch needs components")
    # Only what comes before anything that can act: an event emitted first goes first.
    event = Plan([EmitEvent(event=object()), Spawn(spec=spec("a"))])
    assert quick._first_processes(event, "1")[0] == []
    # In a quick entry, the run's folder only through a params file of the process (written
    # again in the next run's folder), never the run's log folder.
    run = tmp_path / "run"
    run.mkdir()
    (run / "p.yaml").write_text("x: 1\n")
    params = spec("a", argv=("n", "--params-file", f"{run}/p.yaml"))
    files: dict[str, bytes] = {}
    first, _ = quick._first_processes(Plan([Spawn(spec=params)]), "1", str(run), "/log", files)
    assert len(first) == 1 and files == {"p.yaml": b"x: 1\n"}
    for argv in ((f"{run}/missing",), (f"{run}",), (f"{run}/../escape",), ("/log/x",)):
        named = Plan([Spawn(spec=spec("a", argv=("n", *argv)))])
        assert quick._first_processes(named, "1", str(run), "/log")[0] == [], argv


def test_a_node_with_parameters_starts_quick_with_its_params_file(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    prefix = tmp_path / "install"
    program = (  # copies the file after --params-file
        '#!/bin/sh\nwhile [ $# -gt 0 ]; do [ "$1" = --params-file ] && cat "$2" > "$OUT/params.$$"; '
        "shift; done\n"
    )
    install_package(prefix, "qpkg", {"show": program})
    path = tmp_path / "node.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([Node(package='qpkg', executable='show', name='n',\n"
        "                                   parameters=[{'rate': 5, 'frame': 'map'}])])\n"
    )
    env = clean_env(
        XDG_CACHE_HOME=str(tmp_path / "cache"),
        ROS_LOG_DIR=str(tmp_path / "log"),
        AMENT_PREFIX_PATH=str(prefix),
        OUT=str(out),
    )
    env.pop("MLAUNCH_NO_CACHE", None)
    settled(path, tmp_path, prefix)
    seen = []
    for _ in range(2):
        logs = run_logs(tmp_path / "log")
        done = run_mlaunch(str(path), env=env, timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr
        (log_dir,) = run_logs(tmp_path / "log") - logs
        text = (log_dir / "launch.log").read_text()
        seen.append("was started by the quick start" in text)
        (params,) = out.glob("params.*")
        assert "rate: 5" in params.read_text() and "frame: map" in params.read_text()
        params.unlink()
    assert seen == [False, True]


def test_a_damaged_or_foreign_entry_is_never_used(case: tuple[Path, dict[str, str], Path]) -> None:
    path, env, out = case
    run(path, env, out)
    (entry,) = entries(env)
    good = entry.read_bytes()
    # Cut short, a bit flipped, garbage after a right header, others let in: each is ignored
    # (the run resolves, or takes the plan cache's entry) and the run is the same.
    flipped = bytearray(good)
    flipped[-5] ^= 0x40
    for data, mode in (
        (good[: len(good) // 2], 0o600),
        (bytes(flipped), 0o600),
        (quick.FORMAT + b"0" * 40 + b"\n" + b"\xff" * 64, 0o600),
        (good, 0o644),
    ):
        entry.write_bytes(data)
        entry.chmod(mode)
        output, adopted, _ = run(path, env, out)
        assert adopted == [] and "second from one" in output, (data[:60], oct(mode))
        entry.unlink(missing_ok=True)
    # A sound entry of this command line under another command line's name: refused too.
    argv = [str(path), "x:=1"]
    other = entry.with_name(quick.key(argv, env) + quick.SUFFIX)
    other.write_bytes(good)
    other.chmod(0o600)
    logs = run_logs(Path(env["ROS_LOG_DIR"]))
    done = run_mlaunch(*argv, env=env, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    (log_dir,) = run_logs(Path(env["ROS_LOG_DIR"])) - logs
    assert "by the quick start" not in (log_dir / "launch.log").read_text()


# Conformance cases (tests/conformance) whose processes the quick start starts: what they
# record must be what ros2 launch did (their recordings, made from the reference).
QUICK_CASES = [
    "node_basic.launch.py",
    "node_basic.launch.xml",
    "frontend_process.launch.xml",
    "frontend_process.launch.yaml",
    "env_actions.launch.py",
    "typed_values.launch.yaml",
    "ros_scoping.launch.xml",
    "include.launch.xml",
]


@pytest.mark.parametrize("case", QUICK_CASES)
def test_a_quick_start_runs_as_ros2_launch_does(case: str, tmp_path: Path) -> None:
    work = tmp_path / "work"
    prefix = harness.make_prefix(work)
    logs = work / "log"
    logs.mkdir()
    settled(*[p for p in (work, *work.rglob("*")) if not p.is_symlink()])
    cache = {"XDG_CACHE_HOME": str(tmp_path / "cache")}
    expected = harness.expected(case)
    ways = []
    for _ in range(2):  # resolved (the entry written), then quick-started
        before = run_logs(logs)
        summary, _done = harness.run_mlaunch_case(case, work, prefix, (), cache)
        assert summary == expected
        (log_dir,) = run_logs(logs) - before
        ways.append("by the quick start" in (log_dir / "launch.log").read_text())
    assert ways == [False, True]
