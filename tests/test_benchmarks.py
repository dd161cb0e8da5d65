"""The benchmark harness (benchmarks/run.py) runs and reports well-formed results.

Nothing here is about speed: no timing is asserted, only that the harness ran every group,
that each figure has its samples, floor, ratio and target status consistent with each other,
and that the table shows what the JSON holds. The pure parts (launch file generators, the
-X importtime parser, the table) are checked on fixed input.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
import yaml

REPO = Path(__file__).resolve().parent.parent
BENCH = REPO / "benchmarks"
sys.path.insert(0, str(BENCH))

import launchgen as gen  # noqa: E402
import reference  # noqa: E402
import run as bench  # noqa: E402

UNITS = {"s", "lines/s", "cores", "MB", "x", "lines"}


def test_generators_render_one_model_in_three_formats(tmp_path: Path) -> None:
    files = gen.big_system()
    tops = {fmt: gen.write(files, fmt, tmp_path / fmt) for fmt in gen.FORMATS}
    py = tops["py"].read_text()
    compile(py, str(tops["py"]), "exec")
    assert py.count("DeclareLaunchArgument(") == 20
    assert py.count("ExecuteProcess(") == gen.EXECS_PER_FILE
    doc = yaml.safe_load(tops["yaml"].read_text())
    kinds = [next(iter(entry)) for entry in doc["launch"]]
    assert kinds.count("arg") == 20
    root = ET.parse(tops["xml"]).getroot()
    assert root.tag == "launch" and len(root.findall("arg")) == 20
    # The same includes (each scoped in a group) in each format, down to the last level.
    assert len(root.findall("group/include")) == gen.FANOUT
    assert tops["yaml"].read_text().count("- include:") == gen.FANOUT
    assert py.count("IncludeLaunchDescription(") == gen.FANOUT
    for level in range(1, gen.LEVELS + 1):
        for fmt in gen.FORMATS:
            assert (tmp_path / fmt / gen.file_name(f"big_l{level}", fmt)).exists()
    leaf = ET.parse(tmp_path / "xml" / "big_l3.launch.xml").getroot()
    assert not leaf.findall("include")
    executable = leaf.find("group/executable")
    assert executable is not None
    cmd = executable.get("cmd", "")
    assert "$(var robot)_$(var index)" in cmd and "$(env HOME /root)" in cmd


def test_frontend_values_reject_what_the_cmd_split_would_break() -> None:
    with pytest.raises(ValueError, match="must not contain"):
        gen.frontend_value(gen.v("two words"))


def test_many_children_yaml_is_the_ros2_executable_form(tmp_path: Path) -> None:
    path = gen.write([gen.many_children("s", 3, ["/bin/x", "/tmp/f"], "screen")], "yaml", tmp_path)
    doc = yaml.safe_load(path.read_text())
    assert doc == {
        "launch": [
            {"executable": {"cmd": "/bin/x /tmp/f", "name": f"c{i}", "output": "screen"}}
            for i in range(3)
        ]
    }


def test_importtime_parser_takes_the_last_interpreter() -> None:
    header = "import time: self [us] | cumulative | imported package\n"
    first = header + "import time:      5000 |       5000 | ros_wheels_bootstrapper\n"
    second = header + (
        "import time:       300 |        300 |     rclpy.x\n"
        "import time:      1000 |       1300 |   mlaunch.plan.steps\n"
        "import time:      2000 |       3300 | mlaunch.cli\n"
    )
    info = bench.parse_importtime(first + second)
    assert [t["module"] for t in info["top"]] == ["mlaunch.cli", "mlaunch.plan.steps", "rclpy.x"]
    assert [t["depth"] for t in info["top"]] == [0, 1, 2]
    assert info["modules"] == 3 and info["total_ms"] == pytest.approx(3.3)
    assert info["rclpy_imported"] is True


def test_table_shows_targets_and_ratios() -> None:
    results = bench.Results(meta={"mode": "quick", "config": {"runs": 2}, "cpus": 2})
    results.rows.append(
        bench.Row(
            "startup", "demo", "ros", "s", [0.2, 0.1], "floor", [0.05, 0.05], bench.Target(0.12)
        )
    )
    results.skip("sim", "ros", "simulation", "first line\nthe reason")
    text = bench.format_table(results)
    line = next(line for line in text.splitlines() if line.startswith("demo"))
    assert "100.0 ms" in line and "150.0 ms" in line and "3.00" in line and "MISS" in line
    assert "[sim] ros: simulation: the reason" in text


def test_table_shows_ros2_launch_beside_mlaunch() -> None:
    results = bench.Results(meta={"mode": "quick", "config": {"runs": 2}, "cpus": 2})
    row = bench.Row("startup", "demo", "ros", "s", [0.1, 0.1], "floor", [0.05, 0.05])
    row.reference_samples = [0.4, 0.3, 0.5]
    results.rows.append(row)
    results.meta["reference_retries"] = [{"group": "startup", "figure": "py N=1", "reason": "hung"}]
    text = bench.format_table(results)
    line = next(line for line in text.splitlines() if "demo" in line)
    assert "400.0 ms" in line and "0.25" in line and "2.00" in line
    assert "[startup] ros2 launch failed a run of py N=1 (tried again): hung" in text
    data = row.to_json()
    assert data["reference"]["median"] == 0.4 and data["reference"]["best"] == 0.3
    assert data["reference_ratio"] == pytest.approx(0.25)


def _results_json(with_reference: bool) -> dict[str, Any]:
    """A results JSON holding every row the README's table takes, as a run writes it."""
    results = bench.Results(
        meta={
            "mode": "full",
            "config": {"runs": 5},
            "cpus": 2,
            "git": "abc1234",
            "when": "2026-11-29T08:00:00+0000",
            "loadavg_before": [0.5, 0, 0],
            "loadavg_after": [0.7, 0, 0],
        }
    )
    for i, (_, group, name) in enumerate(bench.README_ROWS):
        unit = "lines/s" if group == "output" else "MB" if group == "memory" else "s"
        row = bench.Row(
            group,
            f"4 x 1 {name}" if unit == "lines/s" else name,
            "ros",
            unit,
            [0.02 * (i + 1)],
            "floor",
            [0.01 * (i + 1)],
            bench.Target(0.05),
        )
        if with_reference:
            row.reference_samples = [0.08 * (i + 1)]
        results.rows.append(row)
    # A plain-venv row of the same name is not the one shown.
    results.rows.append(bench.Row("startup", bench.README_ROWS[0][2], "plain", "s", [9.0]))
    return results.to_json()


def test_readme_table_is_written_between_the_markers(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text(
        f"# x\n\nbefore\n{bench.README_BEGIN}\nold table\n{bench.README_END}\nafter\n"
    )
    results = tmp_path / "results.json"
    results.write_text(json.dumps(_results_json(with_reference=True)))
    bench.render_readme(results, readme)
    text = readme.read_text()
    assert "old table" not in text and text.startswith("# x\n\nbefore\n")
    assert text.endswith(f"{bench.README_END}\nafter\n")
    table = [line for line in text.splitlines() if line.startswith("| ")]
    assert table[0].startswith("| figure | mlaunch | floor | ros2 launch |")
    assert len(table) == 1 + len(bench.README_ROWS)
    first = table[1]
    assert first.startswith(f"| {bench.README_ROWS[0][0]} | 20.0 ms | 10.0 ms (floor) | 80.0 ms |")
    assert "| 2.00x / 0.25x | ≤ 50.0 ms |" in first
    assert "commit abc1234" in text and "load average 0.50 before, 0.70 after" in text
    bench.render_readme(results, readme)  # again: the same text, nothing doubled
    assert readme.read_text() == text


def test_readme_table_without_ros2_launch_or_rows_or_markers(tmp_path: Path) -> None:
    table = bench.readme_table(_results_json(with_reference=False))
    assert "| 20.0 ms | 10.0 ms (floor) | - | 2.00x / - |" in table
    # A ratio far below 1 (shutdown against ros2 launch) keeps its digits.
    assert [bench._ratio_text(x) for x in (0.0021, 0.5, None)] == ["0.002x", "0.50x", "-"]
    data = _results_json(with_reference=True)
    data["rows"] = [r for r in data["rows"] if r["group"] != "shutdown"]
    with pytest.raises(bench.BenchError, match="lack the rows of: 100 children gone"):
        bench.readme_table(data)
    readme = tmp_path / "README.md"
    readme.write_text("no markers\n")
    results = tmp_path / "results.json"
    results.write_text(json.dumps(_results_json(with_reference=True)))
    with pytest.raises(bench.BenchError, match="markers"):
        bench.render_readme(results, readme)
    assert readme.read_text() == "no markers\n"


def test_the_project_readme_has_the_markers() -> None:
    text = (REPO / "README.md").read_text()
    assert text.count(bench.README_BEGIN) == 1 and text.count(bench.README_END) == 1
    assert text.index(bench.README_BEGIN) < text.index(bench.README_END)


REFERENCE_PROBE = """
import json, sys
sys.path.insert(0, sys.argv[1])
import launchgen as gen, run as bench
from pathlib import Path
tmp = Path(sys.argv[2])
config = bench.Config(**{**bench.asdict(bench.QUICK), "runs": 1, "reference_output_lines": 200})
results = bench.Results()
harness = bench.Bench(config, [], tmp, results)
bench.pr.become_subreaper()
try:
    path = gen.write(
        [gen.many_children("one", 2, [str(harness.scripts.ready), str(harness.fifo)])],
        "py",
        tmp / "one",
    )
    for i in range(2):
        measure = bench.functools.partial(harness._reference_children, path, 2, 0.0)
        harness.reference_turn("startup", "py N=2", i, measure)
    emit = [str(harness.scripts.emit), "200"]
    out = gen.write([gen.many_children("emit", 2, emit, output="log")], "py", tmp / "emit")
    measure = bench.functools.partial(harness._reference_output, out, "log", 400)
    harness.reference_turn("output", "output=log", 1, measure)
finally:
    bench.pr.kill_descendants()
found = harness.reference is not None
print(json.dumps({"found": found, "runs": harness.reference_runs, "skips": results.to_json()["skipped"]}))
"""


@pytest.mark.skipif(not reference.ENV_SH.exists(), reason=reference.MISSING)
def test_ros2_launch_is_measured_as_mlaunch_is(tmp_path: Path) -> None:
    """The ros2 launch column: one start-up with its shutdown, one output run (few lines), in
    a process of its own (the harness becomes the subreaper of what it starts)."""
    argv = [sys.executable, "-c", REFERENCE_PROBE, str(BENCH), str(tmp_path)]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr[-2000:]
    data = json.loads(done.stdout.splitlines()[-1])
    assert data["found"] and not data["skips"], data
    (one,) = data["runs"]["py N=2"]
    assert 0 < one["first"] <= one["all"] and one["shutdown"] > 0 and one["hwm"] > 0
    (rate,) = data["runs"]["output=log"]
    assert rate["rate"] > 0 and rate["cpu"] > 0


def _check_row(row: dict[str, Any], config: dict[str, Any]) -> None:
    where = f"{row['group']}: {row['name']}"
    assert row["unit"] in UNITS, where
    samples = row["mlaunch"]["samples"]
    assert len(samples) == config["sim_runs" if row["group"] == "sim" else "runs"], where
    assert all(isinstance(x, float | int) and math.isfinite(x) and x >= 0 for x in samples), where
    assert min(samples) <= row["mlaunch"]["median"] <= max(samples), where
    floor = row["floor"]
    if floor is not None:
        assert floor["samples"] and floor["name"], where
        if row["ratio"] is not None:
            assert row["ratio"] == pytest.approx(row["mlaunch"]["median"] / floor["median"])
    ref = row["reference"]
    if ref is not None:
        assert ref["samples"] and ref["name"] == "ros2 launch", where
        ratio = row["reference_ratio"]
        assert ratio == pytest.approx(row["mlaunch"]["median"] / ref["median"]), where
    else:
        assert row["reference_ratio"] is None, where
    target = row["target"]
    if target is not None:
        median, limit = row["mlaunch"]["median"], target["limit"]
        ok = median >= limit if target["op"] == ">=" else median <= limit
        assert target["status"] == ("PASS" if ok else "MISS"), where


def _check_table(table: str, rows: list[dict[str, Any]]) -> None:
    """A header, and a line per row with its status where it has a target."""
    lines = table.splitlines()
    assert any(line.startswith("what") and "mlaunch best" in line for line in lines)
    for row in rows:
        match = [line for line in lines if line.startswith(row["name"] + " ")]
        assert match, row["name"]
        if row["target"] is not None:
            assert any(line.rstrip().endswith(row["target"]["status"]) for line in match)


def _left_behind(domain: str) -> list[str]:
    """Live processes started with this test's private ROS domain (the harness's children)."""
    import psutil

    found = []
    for proc in psutil.process_iter():
        if proc.pid == os.getpid():
            continue
        try:
            if proc.environ().get("ROS_DOMAIN_ID") == domain and proc.status() != "zombie":
                found.append(" ".join(proc.cmdline()))
        except psutil.Error:
            continue
    return found


@pytest.mark.timeout(420)  # past the run's own deadline below (pytest's 120 s came first)
def test_quick_run(tmp_path: Path, ros_env: dict[str, str]) -> None:
    """One quick run in the project venv (the plain venv takes a minute to create once)."""
    out = tmp_path / "bench.json"
    domain = ros_env["ROS_DOMAIN_ID"]
    # Without the ros2 launch column (its runs take longer than mlaunch's whole quick run; the
    # test above measures it): --no-reference.
    argv = [sys.executable, str(BENCH / "run.py"), "--quick", "--venv", "ros", "--no-reference"]
    argv += ["--json", str(out)]
    done = subprocess.run(
        [*argv, "--ros-domain", domain], env=ros_env, capture_output=True, text=True, timeout=360
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert not _left_behind(domain)
    data = json.loads(out.read_text())
    assert data["meta"]["mode"] == "quick"
    rows, skipped = data["rows"], data["skipped"]
    for row in rows:
        _check_row(row, data["meta"]["config"])
    groups = {row["group"] for row in rows} | {s["group"] for s in skipped}
    assert {"startup", "shutdown", "print", "output", "memory", "sim"} <= groups
    names = {row["name"] for row in rows}
    # The one-process Python launch always runs: its start-up, shutdown and --show-args rows.
    assert "first child running, py, N=1" in names
    assert "SIGINT until all gone, N=10" in names
    assert "--show-args one-process launch, py" in names
    # The launcher's CPU to start one child, beside Popen's (benchmarks/spawn_cost.py).
    assert "a child's start, spawning, 300 other fds open" in names
    assert any(row["unit"] == "lines/s" and row["floor"]["name"] == "cat" for row in rows)
    for skip in skipped:
        assert skip["reason"] and "\n" not in skip["reason"]
    imports = data["importtime"]["ros"]
    assert len(imports["top"]) == 10 and isinstance(imports["rclpy_imported"], bool)
    _check_table(done.stdout, rows)


def test_the_fleet_group_is_measured_only_when_named() -> None:
    # (a deploy with Ansible takes minutes: a quick run of every group leaves it out)
    assert "fleet" in bench.GROUPS and "fleet" not in bench.DEFAULT_GROUPS
    assert bench.parse_args(["--only", "fleet"]).only == "fleet"
    with pytest.raises(SystemExit):
        bench.parse_args(["--only", "fleets"])


def test_bisect_measures_a_revision_from_its_own_tree(tmp_path: Path) -> None:
    """benchmarks/bisect_revs.py runs a revision's mlaunch from a temporary worktree (and
    removes it): each round's sample has the launcher's CPU and both wall times."""
    out = tmp_path / "bisect.json"

    def worktrees() -> list[str]:
        listed = subprocess.run(
            ["git", "-C", str(REPO), "worktree", "list", "--porcelain"],
            capture_output=True,
            text=True,
            check=True,
        )
        return [line for line in listed.stdout.splitlines() if line.startswith("worktree ")]

    before = worktrees()
    argv = [sys.executable, str(BENCH / "bisect_revs.py"), "--runs", "2", "--n", "3", "--calls"]
    argv.append("--floor")
    done = subprocess.run(
        [*argv, "--json", str(out), "HEAD"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr[-2000:]
    # its own trees are gone (other worktrees of the repository may come and go meanwhile)
    left = [w for w in set(worktrees()) - set(before) if "mlaunch-bisect-" in w]
    assert not left, left
    data = json.loads(out.read_text())
    head = subprocess.run(
        ["git", "-C", str(REPO), "rev-parse", "HEAD"], capture_output=True, text=True, check=True
    ).stdout.strip()[:7]
    [subject, floor] = data["subjects"]
    assert subject["label"] == head and len(subject["samples"]) == 2
    assert floor["label"] == "floor" and len(floor["samples"]) == 2 and floor["calls"] is None
    for sample in subject["samples"] + floor["samples"]:
        assert sample["cpu"] > 0 and 0 < sample["first"] <= sample["all"]
    # Python calls to the first and to the third child started, and the modules loaded by then.
    first, every, modules = subject["calls"]
    assert 0 < first < every and modules > 50
    assert f"\n{head} " in done.stdout and "\nfloor " in done.stdout
    assert "CPU/floor" in done.stdout  # each revision's ratio to the bare Popen loop


def test_bisect_spreads_revisions_over_the_history() -> None:
    import bisect_revs

    history = subprocess.run(
        ["git", "-C", str(REPO), "rev-list", "--first-parent", "--max-count=5", "HEAD"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    if len(history) < 5:
        pytest.skip("a shallow clone: fewer than 5 commits of history")
    old, new = history[-1], history[0]
    assert bisect_revs.spread(old, new, 2) == [old, history[2], new]
    assert bisect_revs.spread(old, new, 10) == history[::-1]


def test_autoware_is_its_own_group_and_skips_without_sources(tmp_path: Path) -> None:
    """--only autoware selects it; a plain run does not start it (minutes, fetched sources);
    without the pinned archives it is one clear line naming the command that gets them."""
    import autoware_bench

    assert "autoware" in bench.GROUPS and "autoware" not in bench.DEFAULT_GROUPS
    assert bench.parse_args(["--only", "autoware"]).only == "autoware"
    said: list[str] = []
    reason = autoware_bench.measure(
        1, Path("mlaunch"), Path("python"), {}, tmp_path, said.append, cache=tmp_path
    )
    assert isinstance(reason, str) and not said
    assert f"no Autoware sources in {tmp_path / 'sources'}" in reason
    assert "benchmarks/autoware_tree.py" in reason and "\n" not in reason


def test_autoware_watch_tells_the_launch_from_the_launcher(tmp_path: Path) -> None:
    """The fixture's processes (recorders before and after their exec, containers) and the
    tree's xacro are not the launcher's; a helper of the launcher (its guard) is."""
    import autoware_bench as ab
    import autoware_container

    prefix = tmp_path / "prefix"
    assert ab.is_fixture(["sleep", "2147483647"], prefix)
    assert ab.is_fixture(["/bin/sh", str(prefix / "lib/pkg/exe"), "--ros-args"], prefix)
    assert ab.is_fixture(["/venv/bin/python", "/x/benchmarks/autoware_container.py"], prefix)
    assert not ab.is_fixture(["launch-guard [run 12]"], prefix)
    assert ab._label(["launch-guard [run 12]"]) == "launch-guard"  # one name in every run
    assert not ab.is_fixture(["/bin/sh", "/usr/lib/other"], prefix)
    assert ab.is_tree_command(["/venv/bin/python", "/venv/bin/xacro", "vehicle.xacro"])
    assert not ab.is_tree_command(["/venv/bin/python", "/venv/bin/mlaunch", "x.launch.xml"])
    assert autoware_container.default_name("autoware::planning::PlannerNode") == "plannernode"
    plugins = autoware_container.AnyPlugin()
    assert plugins.get(("any_pkg", "ns::Thing"))[0] == "thing" and len(plugins) == 0


def test_autoware_fixture_lays_out_a_prefix_of_stand_ins(tmp_path: Path) -> None:
    """From pinned archives to an ament prefix: each package's share folder and index entry,
    a recorder for every executable the tree starts (a stub package for one the sources lack),
    the container stand-in for rclcpp_components' containers; a tree of the wrong size is said."""
    import tarfile

    import autoware_tree as fixture

    top = tmp_path / "src" / "autoware_launch"
    (top / "autoware_launch" / "launch").mkdir(parents=True)
    (top / "autoware_launch" / "src").mkdir()
    (top / "autoware_launch" / "package.xml").write_text(
        "<package><name>autoware_launch</name></package>"
    )
    (top / "autoware_launch" / "src" / "main.cpp").write_text("int main() {}")
    (top / "autoware_launch" / "launch" / "planning_simulator.launch.xml").write_text(
        '<launch>\n  <arg name="map_path"/>\n'
        '  <node pkg="autoware_launch" exec="planner" name="planner"/>\n'
        '  <node pkg="robot_state_publisher" exec="robot_state_publisher"/>\n'
        '  <node_container pkg="rclcpp_components" exec="component_container" name="c"'
        ' namespace="">\n'
        '    <composable_node pkg="x" plugin="x::Y" name="y"/>\n  </node_container>\n</launch>\n'
    )
    sources = tmp_path / "sources"
    sources.mkdir()
    with tarfile.open(sources / "autoware_launch.tar.gz", "w:gz") as tar:
        tar.add(top, arcname="autoware_launch")
    (sources / "MANIFEST.tsv").write_text("archive\nautoware_launch.tar.gz\n")
    cache = tmp_path / "cache"
    with pytest.raises(fixture.FixtureError, match="3 processes and 1 composable nodes, not"):
        fixture.build(sources, cache)
    tree = fixture.build(sources, cache, size=(3, 1))
    prefix = tree.prefix
    assert (prefix / ".built").is_file() and tree.launch_file.is_file()
    assert not (prefix / "share/autoware_launch/src").exists()  # compiled, not installed
    index = prefix / "share/ament_index/resource_index/packages"
    assert sorted(p.name for p in index.iterdir()) == [
        "autoware_launch", "rclcpp_components", "robot_state_publisher"]  # fmt: skip
    for recorder in ("autoware_launch/planner", "robot_state_publisher/robot_state_publisher"):
        text = (prefix / "lib" / recorder).read_text()
        assert os.access(prefix / "lib" / recorder, os.X_OK) and f"p {recorder}" in text
    container = (prefix / "lib/rclcpp_components/component_container").read_text()
    assert str(fixture.CONTAINER) in container
    # Built once: a second call finds it.
    assert fixture.build(sources, cache, size=(3, 1)) == tree


def test_startup_buckets_add_up_to_the_marks() -> None:
    import startup_profile

    found = startup_profile.buckets([("interpreter", 0.010), ("imports", 0.025), ("spawn", 0.026)])
    assert found == pytest.approx(
        {
            "interpreter": 0.010,
            "imports": 0.015,
            "spawn": 0.001,
            "total until the first child runs": 0.026,
        }
    )


def test_startup_profile_follows_mlaunch_to_its_first_child(tmp_path: Path) -> None:
    """Every step of a run's way to its first child is a bucket, from the process's exec."""
    import startup_profile

    path = gen.write([gen.many_children("t", 1, ["true"])], "py", tmp_path / "launch")
    env = {**os.environ, "ROS_LOG_DIR": str(tmp_path / "logs"), "MLAUNCH_NO_CACHE": "1"}
    found = startup_profile.profile([sys.executable, "-m", "mlaunch", str(path)], env, 1)
    steps = [
        "interpreter and site (from exec)",
        "import mlaunch.cli",
        "import app.pipeline (argparse, options), engine.lifeline",
        "parse the command line",
        "lifeline (params folder, cgroup, guard fork)",
        "load the launch file",
        "resolve",
        # The first processes start before the supervisor is made (mlaunch.app.quick).
        "supervise: the descriptor limit, the first spawns' set-up",
        "spawn of the first child",
    ]
    assert [s for s in steps if s not in found] == []
    assert all(len(v) == 1 and v[0] >= 0 for v in found.values())
    total = found.pop("total until the first child runs")[0]
    assert sum(v[0] for v in found.values()) == pytest.approx(total)


def test_startup_profile_follows_mlaunch_to_its_nth_child(tmp_path: Path) -> None:
    """--children N: the starts after the first are one bucket, the total ends at the N-th."""
    import startup_profile

    path = gen.write([gen.many_children("t", 5, ["true"])], "py", tmp_path / "launch")
    env = {**os.environ, "ROS_LOG_DIR": str(tmp_path / "logs"), "MLAUNCH_NO_CACHE": "1"}
    argv = [sys.executable, "-m", "mlaunch", str(path)]
    found = startup_profile.profile(argv, env, 1, children=5)
    assert "spawn of the first child" in found and "spawns of children 2 to 5" in found
    total = found.pop("total to 5 started")[0]
    assert sum(v[0] for v in found.values()) == pytest.approx(total)
