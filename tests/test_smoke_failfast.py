"""`mlaunch test` ends the wait at once on a failure that cannot heal (issue 32 item 1), and its
verdict says how long it watched after ready."""

from __future__ import annotations

import importlib.util
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from procutil import clean_env, demo_package, run_mlaunch

from mlaunch.smoke.report import Window

# A deadline far beyond what any of these runs takes: a verdict that waits for it is the bug.
FAR = "120"

REFUSED = """launch:
- node_container:
    pkg: rclcpp_components
    exec: component_container
    name: box
    namespace: ""
    composable_node:
    - {pkg: robot_state_publisher, plugin: "robot_state_publisher::RobotStatePublisher",
       name: rsp, param: [{name: robot_description, value: "<robot name='r'><link name='a'/></robot>"}]}
    - {pkg: composition, plugin: "composition::Nope", name: nope}
"""

ONE_SHOT_OUTPUT = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[sys.executable, "-c", "print('hello')"], name="once"),
        ExecuteProcess(cmd=[sys.executable, "-c", "import time; time.sleep(60)"], name="steady"),
    ])
"""

STEADY = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[sys.executable, "-c", "import time; time.sleep(60)"], name="steady"),
    ])
"""


def _row(out: str, text: str) -> str:
    table = out[out.rindex("\nmlaunch test ") :]
    return next(line.strip() for line in table.splitlines() if text in line)


def _properties(report: Path) -> dict[str, str]:
    suite = ET.parse(report).getroot().find("testsuite")
    assert suite is not None
    return {p.get("name", ""): p.get("value", "") for p in suite.iter("property")}


@pytest.mark.skipif(
    importlib.util.find_spec("composition_interfaces") is None
    or importlib.util.find_spec("rclpy") is None,
    reason="the container stand-in needs rclpy and composition_interfaces (./scripts/setup)",
)
def test_a_refused_composable_load_fails_at_once(tmp_path: Path, ros_env: dict[str, str]) -> None:
    path = tmp_path / "refused.launch.yaml"
    path.write_text(REFUSED)
    done = run_mlaunch("test", str(path), "--timeout", FAR, env=clean_env(), timeout=100)
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    row = _row(done.stdout, "node /nope")
    assert row.startswith("FAIL") and "container /box refused to load composition::Nope" in row
    assert "deadline" not in row, out
    assert "never ready: stopped at a failure" in done.stdout, done.stdout


def test_the_output_of_a_process_that_ended_for_good_cannot_match_any_more(
    tmp_path: Path,
) -> None:
    path = tmp_path / "once.launch.py"
    path.write_text(ONE_SHOT_OUTPUT)
    args = ("test", str(path), "--timeout", FAR, "--expect-output", "once:never printed")
    done = run_mlaunch(*args, env=clean_env(), timeout=100)
    assert done.returncode == 1, done.stdout + done.stderr
    row = _row(done.stdout, "output of once")
    assert "no line matched before once-1 ended (exited with status 0)" in row, done.stdout
    assert "deadline" not in row


def test_a_node_whose_process_ended_for_good_cannot_appear(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    pytest.importorskip("rclpy")
    prefix = demo_package(tmp_path)  # its talker prints and exits 0: it never joins the graph
    path = tmp_path / "node.launch.yaml"
    path.write_text(
        "launch:\n- node: {pkg: demo, exec: talker, name: talker}\n"
        '- executable: {cmd: "sleep 60", name: steady}\n'  # the launch is not idle: it waits
    )
    env = clean_env(AMENT_PREFIX_PATH=prefix)
    done = run_mlaunch("test", str(path), "--timeout", FAR, env=env, timeout=100)
    assert done.returncode == 1, done.stdout + done.stderr
    row = _row(done.stdout, "node /talker")
    assert "it cannot appear: talker-1 ended (exited with status 0)" in row, done.stdout
    assert "deadline" not in row


def test_the_verdict_says_how_long_it_watched_after_ready(tmp_path: Path) -> None:
    path = tmp_path / "steady.launch.py"
    path.write_text(STEADY)
    report = tmp_path / "report.xml"
    done = run_mlaunch("test", str(path), "--hold", "1", "--junit", str(report), env=clean_env())
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"then watched \d+\.\d s \(--hold 1\): a failure after ", done.stdout)
    properties = _properties(report)
    assert properties["hold"] == "1"
    assert float(properties["watched_after_ready"]) >= 1.0
    assert float(properties["ready_after"]) > 0


def test_the_window_line_for_each_ending() -> None:
    assert Window(None, 3, 2.5).line(True) == "never ready: stopped at a failure 2.5 s in"
    assert Window(2.0, 3, 3.2).line(True) == "ready after 2.0 s; failed 1.2 s into the 3 s hold"
    assert Window(2.0, 3, 5.0).line(False) == (
        "ready after 2.0 s, then watched 3.0 s (--hold 3): a failure after 5.0 s is not seen"
    )
    assert Window(None, 3, 1.0).properties()["ready_after"] == ""
