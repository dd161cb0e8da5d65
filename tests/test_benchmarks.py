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


def test_quick_run(tmp_path: Path, ros_env: dict[str, str]) -> None:
    """One quick run in the project venv (the plain venv takes a minute to create once)."""
    out = tmp_path / "bench.json"
    domain = ros_env["ROS_DOMAIN_ID"]
    argv = [sys.executable, str(BENCH / "run.py"), "--quick", "--venv", "ros", "--json", str(out)]
    done = subprocess.run(
        [*argv, "--ros-domain", domain], env=ros_env, capture_output=True, text=True, timeout=150
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
    assert any(row["unit"] == "lines/s" and row["floor"]["name"] == "cat" for row in rows)
    for skip in skipped:
        assert skip["reason"] and "\n" not in skip["reason"]
    imports = data["importtime"]["ros"]
    assert len(imports["top"]) == 10 and isinstance(imports["rclpy_imported"], bool)
    _check_table(done.stdout, rows)
