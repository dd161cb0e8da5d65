"""The plan cache (mlaunch.app.plan_cache, mlaunch.plan.inputs): a repeated start takes its plan
from disk, the plan is the one a fresh resolution makes, and any change of an input, or an input
the recording cannot see, means resolving again.

Each test has a cache folder of its own (XDG_CACHE_HOME in its tmp_path) and reads what the cache
did from ``--debug``'s ``mlaunch: plan cache:`` lines.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from procutil import REPO, clean_env, install_package, run_mlaunch

from mlaunch.app import plan_cache
from mlaunch.plan import inputs

sys.path.insert(0, str(Path(__file__).resolve().parent / "conformance"))
import harness

HIT = "inputs unchanged"
STORED = "plan cache: stored"

# A variety of launch files, every format and feature: includes, conditions, OpaqueFunction,
# timers and event handlers, composable nodes, lifecycle, newer syntax, roslaunch files.
VARIETY = [
    "launches/examples/include.launch.py",
    "launches/examples/include.launch.xml",
    "launches/examples/scoping.launch.yaml",
    "launches/jtbot_sim.launch.xml",
    "launches/smartcar_display.launch",
    "tests/conformance/cases/conditions.launch.py",
    "tests/conformance/cases/launch_configurations.launch.py",
    "tests/conformance/cases/timers.launch.py",
    "tests/conformance/cases/typed_values.launch.yaml",
    "tests/conformance/component_cases/deferred.launch.xml",
    "tests/conformance/component_cases/nav2_like.launch.py",
    "tests/conformance/component_cases/params_files.launch.yaml",
    "tests/launches/composition/demo.launch.py",
    "tests/launches/lifecycle_events.launch.py",
    "tests/launches/newer/loop.launch.yaml",
    "tests/ros1diff/sim/rrbot_gazebo/launch/rrbot_world.launch",
]


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(XDG_CACHE_HOME=str(tmp_path / "cache"))


def entries(env: dict[str, str]) -> list[Path]:
    folder = Path(env["XDG_CACHE_HOME"]) / "mlaunch" / "plans"
    return sorted(folder.glob("*.plan")) if folder.is_dir() else []


def cache_lines(done: subprocess.CompletedProcess[str]) -> str:
    return "\n".join(x for x in done.stderr.splitlines() if "mlaunch: plan cache:" in x)


def printed(path: str | Path, env: dict[str, str], *more: str) -> subprocess.CompletedProcess[str]:
    done = run_mlaunch(str(path), "--print", "--debug", *more, env=env, timeout=60)
    assert done.returncode == 0, done.stderr
    return done


def from_the_cache(path: Path, env: dict[str, str], *more: str) -> subprocess.CompletedProcess[str]:
    """--print of ``path`` that took its plan from the cache. The source package search lists
    the repository's folders, which the suite running beside may change (a new entry is a new
    resolve, rightly): a few tries, each miss saying why."""
    misses = []
    for _ in range(3):
        done = printed(path, env, *more)
        if HIT in cache_lines(done):
            return done
        misses.append(cache_lines(done))
    raise AssertionError("never from the cache:\n" + "\n".join(misses))


@pytest.mark.parametrize("name", VARIETY)
def test_a_cached_plan_prints_as_a_fresh_one(name: str, env: dict[str, str]) -> None:
    path = REPO / name
    fresh = printed(path, env, "--format", "json")
    assert STORED in cache_lines(fresh), cache_lines(fresh)
    cached = from_the_cache(path, env, "--format", "json")
    assert cached.stdout == fresh.stdout
    json.loads(cached.stdout)
    text = from_the_cache(path, env)  # the text form of the same key's plan (--format is not in it)
    assert text.stdout == printed(path, env, "--no-cache").stdout


# Conformance cases whose runs from the cache must record what ros2 launch did: timers, an
# OnExecutionComplete handler (matched by the action's identity), params files written again in
# the new run's folder, environment actions, includes, late binding, ROS scoping.
RUN_CASES = [
    "timers.launch.py",
    "execution_complete.launch.py",
    "typed_values.launch.yaml",
    "env_actions.launch.py",
    "include.launch.xml",
    "late_binding.launch.py",
    "ros_scoping.launch.xml",
]


def run_case(case: str, work: Path, prefix: Path) -> tuple[dict[str, object], str]:
    """The conformance summary of one mlaunch run of ``case`` in ``work``, and its cache notes
    (--debug's ``mlaunch: plan cache:`` lines, which the summary, as a ros2 launch run's, reads
    neither as log nor as output)."""
    cache = {"XDG_CACHE_HOME": str(work.parent / "cache")}
    summary, done = harness.run_mlaunch_case(case, work, prefix, ["--debug"], cache)
    return summary, cache_lines(done)


@pytest.mark.parametrize("case", RUN_CASES)
def test_a_cached_plan_runs_as_ros2_launch_does(case: str, tmp_path: Path) -> None:
    work = tmp_path / "work"
    prefix = harness.make_prefix(work)
    (work / "log").mkdir()  # ROS_LOG_DIR: made by the first run in a folder the search lists
    expected = harness.expected(case)
    fresh, notes = run_case(case, work, prefix)
    assert STORED in notes, notes
    assert fresh == expected
    cached, notes = run_case(case, work, prefix)
    assert HIT in notes, notes
    assert cached == expected


def test_no_cache_and_the_variable_leave_it_alone(tmp_path: Path, env: dict[str, str]) -> None:
    path = REPO / VARIETY[0]
    printed(path, env, "--no-cache")
    printed(path, {**env, "MLAUNCH_NO_CACHE": "1"})
    assert entries(env) == []
    printed(path, {**env, "MLAUNCH_NO_CACHE": "0"})
    (entry,) = entries(env)
    assert entry.stat().st_mode & 0o777 == 0o600
    assert entry.parent.stat().st_mode & 0o777 == 0o700


# --- what invalidates a plan ---------------------------------------------------------------------

TREE_TOP = """\
import os
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, IncludeLaunchDescription
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import EnvironmentVariable, LaunchConfiguration, ThisLaunchFileDir

HERE = os.path.dirname(__file__)


def generate_launch_description():
    with open(os.path.join(HERE, 'extra.txt')) as f:  # a file the launch file reads itself
        extra = f.read().strip()
    return LaunchDescription([
        DeclareLaunchArgument('mode', default_value='fast'),
        ExecuteProcess(cmd=['echo', LaunchConfiguration('mode'), extra,
                            EnvironmentVariable('CACHE_TEST_VAR', default_value='unset')]),
        IncludeLaunchDescription(AnyLaunchDescriptionSource([ThisLaunchFileDir(), '/inc.launch.xml'])),
    ])
"""

TREE_INCLUDED = """\
<launch>
  <node pkg="cachepkg" exec="tool" name="tool"><param from="$(dirname)/params.yaml"/></node>
  <executable cmd="echo included $(find-pkg-share cachepkg)"/>
</launch>
"""


def tree(root: Path) -> tuple[Path, dict[str, Path]]:
    root.mkdir(parents=True, exist_ok=True)
    (root / "top.launch.py").write_text(TREE_TOP)
    (root / "inc.launch.xml").write_text(TREE_INCLUDED)
    (root / "extra.txt").write_text("one\n")
    (root / "params.yaml").write_text("/**:\n  ros__parameters:\n    speed: 1\n")
    prefix = install_package(root / "install", "cachepkg", {"tool": "#!/bin/sh\necho tool\n"})
    return root / "top.launch.py", {"prefix": prefix}


@pytest.fixture
def tree_env(tmp_path: Path, env: dict[str, str]) -> tuple[Path, dict[str, str]]:
    top, places = tree(tmp_path / "tree")
    env = {**env, "AMENT_PREFIX_PATH": str(places["prefix"])}
    env.pop("CACHE_TEST_VAR", None)
    return top, env


def resolve_twice(top: Path, env: dict[str, str], *args: str) -> tuple[str, str]:
    """--print of ``top`` (stored), then again (from the cache): the two cache notes."""
    first = printed(top, env, "--format", "json", *args)
    second = printed(top, env, "--format", "json", *args)
    assert second.stdout == first.stdout
    return cache_lines(first), cache_lines(second)


def test_a_repeated_start_hits_and_any_change_resolves_again(
    tree_env: tuple[Path, dict[str, str]],
) -> None:
    top, env = tree_env
    first, second = resolve_twice(top, env)
    assert STORED in first and HIT in second

    def changed(edit: str) -> str:
        done = printed(top, env, "--format", "json")
        lines = cache_lines(done)
        assert "resolving again" in lines, f"{edit}: {lines}"
        assert STORED in lines
        assert HIT in cache_lines(printed(top, env, "--format", "json")), edit
        return done.stdout

    root = top.parent
    (root / "extra.txt").write_text("two\n")  # a file the launch file opened itself
    assert "two" in changed("extra.txt")
    (root / "inc.launch.xml").write_text(TREE_INCLUDED.replace("echo included", "echo again"))
    assert "again" in changed("the included file")
    (root / "params.yaml").write_text("/**:\n  ros__parameters:\n    speed: 2\n")
    assert '"speed": 2' in changed("the params file").replace(" ", "").replace(
        '"speed":2', '"speed": 2'
    )
    top.write_text(TREE_TOP.replace("'fast'", "'slow'"))
    assert "slow" in changed("the launch file")


def test_the_environment_and_arguments_are_in_the_key(
    tree_env: tuple[Path, dict[str, str]],
) -> None:
    top, env = tree_env
    resolve_twice(top, env)
    other = {**env, "CACHE_TEST_VAR": "set"}
    first, second = resolve_twice(top, other)
    assert STORED in first and HIT in second
    assert "set" in printed(top, other, "--format", "json").stdout
    first, second = resolve_twice(top, env, "mode:=careful")
    assert STORED in first and HIT in second
    assert len(entries(env)) == 3
    # back to the first: its entry is still there
    assert HIT in cache_lines(printed(top, env, "--format", "json"))


def test_a_package_added_resolves_again(tmp_path: Path, env: dict[str, str]) -> None:
    """A package added to a prefix the search listed: the plan found it elsewhere (or not)."""
    top = tmp_path / "pkg.launch.xml"
    top.write_text('<launch><executable cmd="echo $(find-pkg-prefix cachepkg)"/></launch>\n')
    first_prefix = install_package(tmp_path / "first", "other", {})
    second_prefix = install_package(tmp_path / "second", "cachepkg", {})
    env = {**env, "AMENT_PREFIX_PATH": os.pathsep.join([str(first_prefix), str(second_prefix)])}
    _first, second = resolve_twice(top, env)
    assert HIT in second
    install_package(first_prefix, "cachepkg", {})  # now found in the first prefix
    done = printed(top, env, "--format", "json")
    assert "resolving again" in cache_lines(done)
    assert str(first_prefix) in done.stdout


# --- what cannot be cached -----------------------------------------------------------------------

UNCACHEABLE = {
    "subprocess": (
        "import subprocess\nVALUE = subprocess.run(['true']).returncode",
        "runs a program",
    ),
    "time": ("import time\nVALUE = int(time.time())", "reads the time"),
    "datetime": ("import datetime\nVALUE = datetime.datetime.now().year", "reads the time"),
    "random": ("import random\nVALUE = random.randint(0, 9)", "reads random numbers"),
    "uuid": ("import uuid\nVALUE = uuid.uuid4().hex", "random bytes"),
    "socket": (
        "import socket\ntry:\n    socket.getaddrinfo('localhost', 1)\nexcept OSError:\n    pass\n"
        "VALUE = 1",
        "uses the network",
    ),
    "write": (
        "import os, tempfile\nVALUE = 1\nopen(os.path.join(os.path.dirname(__file__), 'out.txt'),"
        " 'w').write('x')",
        "writes",
    ),
    "environ": ("import os\nos.environ['CACHE_TEST_SET'] = '1'\nVALUE = 1", "os.environ"),
    "lambda": ("VALUE = 1\nLATE = lambda context: []", "defined in the launch file"),
}

PY_LAUNCH = """\
from launch import LaunchDescription
from launch.actions import ExecuteProcess, OpaqueFunction, TimerAction
{code}


def generate_launch_description():
    actions = [ExecuteProcess(cmd=['echo', str(VALUE)])]
    if 'LATE' in globals():
        actions.append(TimerAction(period=1.0, actions=[OpaqueFunction(function=LATE)]))
    return LaunchDescription(actions)
"""


@pytest.mark.parametrize("what", sorted(UNCACHEABLE))
def test_what_the_recording_cannot_see_is_not_cached(
    what: str, tmp_path: Path, env: dict[str, str]
) -> None:
    code, reason = UNCACHEABLE[what]
    top = tmp_path / f"{what}.launch.py"
    top.write_text(PY_LAUNCH.format(code=code))
    done = printed(top, env)
    assert "not stored: " in cache_lines(done) and reason in cache_lines(done), cache_lines(done)
    assert entries(env) == []
    # --print says so without --debug too, in one line
    quiet = run_mlaunch(str(top), "--print", env=env, timeout=60)
    (line,) = [x for x in quiet.stderr.splitlines() if "plan cache" in x]
    assert reason in line


def test_anonymous_names_are_new_in_every_run(tmp_path: Path, env: dict[str, str]) -> None:
    top = tmp_path / "anon.launch.xml"
    top.write_text('<launch><executable cmd="echo $(anon talker)"/></launch>\n')
    done = printed(top, env)
    assert "$(anon talker) is a new name in every run" in cache_lines(done)
    assert entries(env) == []


# --- entries that are not trusted ----------------------------------------------------------------


def test_a_corrupt_entry_is_ignored_with_one_line(tmp_path: Path, env: dict[str, str]) -> None:
    path = REPO / VARIETY[0]
    fresh = printed(path, env, "--format", "json")
    (entry,) = entries(env)
    data = bytearray(entry.read_bytes())
    data[-10] ^= 0xFF
    entry.write_bytes(bytes(data))
    done = run_mlaunch(str(path), "--print", "--format", "json", env=env, timeout=60)
    assert done.returncode == 0, done.stderr
    (line,) = [x for x in done.stderr.splitlines() if "plan cache" in x]
    assert "ignored" in line and "digest does not match" in line
    assert done.stdout == fresh.stdout
    assert HIT in cache_lines(printed(path, env, "--format", "json"))  # stored again


def test_an_entry_others_could_write_is_never_read(tmp_path: Path, env: dict[str, str]) -> None:
    path = REPO / VARIETY[0]
    fresh = printed(path, env, "--format", "json")
    (entry,) = entries(env)
    entry.chmod(0o664)
    done = printed(path, env, "--format", "json")
    assert "lets others in" in cache_lines(done)
    assert HIT not in cache_lines(done)
    assert done.stdout == fresh.stdout
    entry.chmod(0o600)
    entry.parent.chmod(0o777)
    try:
        done = printed(path, env, "--format", "json")
        assert "has mode 777" in cache_lines(done)
    finally:
        entry.parent.chmod(0o700)


def test_a_foreign_entry_is_not_unpickled(tmp_path: Path, env: dict[str, str]) -> None:
    """An entry whose digest is right but made for another key (copied from elsewhere) is
    refused before its pickle is read."""
    path = REPO / VARIETY[0]
    printed(path, env, "--format", "json")
    (first,) = entries(env)
    other = REPO / VARIETY[1]
    printed(other, env, "--format", "json")
    (second,) = set(entries(env)) - {first}
    shutil.copy(first, second)
    done = printed(other, env, "--format", "json")
    assert "made for another key" in cache_lines(done)


def test_the_folder_is_bounded(tmp_path: Path) -> None:
    folder = tmp_path / "plans"
    folder.mkdir(mode=0o700)
    for i in range(6):
        entry = folder / f"{i}.plan"
        entry.write_bytes(b"x" * 1000)
        os.utime(entry, ns=(i * 10**9, i * 10**9))
    cache = plan_cache.PlanCache(str(folder), "k", lambda text: None, False, limit=2500)
    cache._prune()
    assert sorted(p.name for p in folder.iterdir()) == ["4.plan", "5.plan"]


# --- the recording itself ------------------------------------------------------------------------


def test_the_recording_notes_stats_listings_and_reads(tmp_path: Path) -> None:
    (tmp_path / "a.txt").write_text("a")
    (tmp_path / "sub").mkdir()
    with inputs.record() as recording:
        os.path.exists(tmp_path / "missing")
        os.path.isfile(tmp_path / "a.txt")
        os.listdir(tmp_path / "sub")
        (tmp_path / "a.txt").read_text()
    found = recording.inputs
    assert str(tmp_path / "a.txt") in found.files
    assert str(tmp_path / "sub") in found.listings
    assert ("stat", str(tmp_path / "missing")) in found.probes
    assert found.changed() is None
    (tmp_path / "missing").write_text("")
    assert found.changed() == f"{tmp_path / 'missing'} changed (stat)"
    assert recording.refusals == []
    assert os.stat.__name__ == "stat"  # unwrapped after the window


def test_the_clock_and_programs_refuse_the_plan() -> None:
    code = "import time\ntime.time()\n"
    with inputs.record() as recording:
        time_now = __import__("time").time()  # this test file: code other than mlaunch's
    assert time_now > 0
    assert any("reads the time" in r for r in recording.refusals)
    with inputs.record() as recording:
        subprocess.run([sys.executable, "-c", code], check=True)
    assert any("runs a program" in r for r in recording.refusals)


def test_an_edit_that_keeps_size_and_time_is_seen(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A file's identity spares reading it again only while its change time (the kernel's,
    which no one can set back) is the same: an edit of the same size, with its modification
    time put back, still reads as a change."""
    monkeypatch.setattr(inputs, "RACY_NS", 0)  # every file settled at once
    path = tmp_path / "params.yaml"
    path.write_text("speed: 1\n")
    with inputs.record() as recording:
        path.read_text()
    found = inputs.Inputs.from_data(recording.inputs.as_data())
    assert str(path) in found.unchanged
    assert found.changed() is None
    before = path.stat()
    path.write_text("speed: 2\n")
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))
    assert path.stat().st_size == before.st_size
    assert found.changed() == f"{path} changed"


def test_code_imported_before_the_window_is_an_input(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A module of a user's or of site-packages that was imported before loading began (so no
    open() shows it) is an input too: an upgrade of it is a change."""
    (tmp_path / "helper_for_the_cache_test.py").write_text("VALUE = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    __import__("helper_for_the_cache_test")
    try:
        with inputs.record() as recording:
            pass
    finally:
        del sys.modules["helper_for_the_cache_test"]
    assert str(tmp_path / "helper_for_the_cache_test.py") in recording.inputs.files
    assert not any(path.startswith(os.path.dirname(os.__file__)) for path in recording.inputs.files)


SLOW_TOP = """\
import time
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    time.sleep(1.0)  # still loading when the run's move into its cgroup is done
    return LaunchDescription([ExecuteProcess(cmd=['true'])])
"""


def test_the_runs_own_cgroup_move_is_not_the_launchs_write(
    tmp_path: Path, env: dict[str, str]
) -> None:
    """The move into the run's cgroup runs in a thread while the file loads; its write of
    cgroup.procs is mlaunch's, not the launch file's: a cold run still stores its plan (a fresh
    clone's CI lost a store to it). The move is held 0.3 s so it lands inside the loading."""
    from mlaunch.engine.cgroup import RunCgroup

    made, why = RunCgroup.create(dict(os.environ))
    if made is None:
        pytest.skip(f"no cgroup of its own for a run here: {why}")
    made.remove()
    top = tmp_path / "slow.launch.py"
    top.write_text(SLOW_TOP)
    code = (
        "import sys, time\n"
        "import mlaunch.engine.cgroup as cgroup\n"
        "enter = cgroup.RunCgroup.enter\n"
        "def held(self):\n"
        "    time.sleep(0.3)\n"
        "    return enter(self)\n"
        "cgroup.RunCgroup.enter = held\n"
        "from mlaunch.cli import main\n"
        "sys.exit(main(sys.argv[1:]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, str(top), "--print", "--debug"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert STORED in cache_lines(done), cache_lines(done)
