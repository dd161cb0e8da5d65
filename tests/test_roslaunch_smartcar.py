"""The ROS 1 smartcar seed's launch file: it resolves and runs here, and equals its conversion."""

from __future__ import annotations

import os
import re
import signal
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import Running, clean_env
from test_interfaces import HAVE_TF2_MSGS
from test_roslaunch import params, plan_of, summarize

from mlaunch.cli import main as mlaunch_main
from mlaunch.commands import convert
from mlaunch.ros import packages
from mlaunch.ros.search import PackageSearch, searching

REPO = Path(__file__).resolve().parent.parent
LAUNCH = REPO / "launches" / "smartcar_display.launch"
TWIN = REPO / "launches" / "smartcar_display.launch.py"
ROBOTS = REPO / "robots"

pytestmark = requires_rclpy  # the ROS programs are stand-ins, which need rclpy


@pytest.fixture(autouse=True)
def static_transform_standin(monkeypatch: pytest.MonkeyPatch) -> None:
    """Plans made in this process count the static_transform_publisher stand-in as available
    whether or not tf2_msgs is installed: no process is started from them."""
    from mlaunch import standins

    monkeypatch.setattr(standins, "NEEDS", {})


@pytest.fixture(autouse=True)
def robots_found() -> Iterator[None]:
    """smartcar_description is a source package of this repository (also for files in tmp)."""
    packages.forget_scans()
    with searching(PackageSearch([str(ROBOTS)])):
        yield
    packages.forget_scans()


def test_print_shows_the_ros2_plan_without_error() -> None:
    env = clean_env()
    env.pop("AMENT_PREFIX_PATH", None)
    run = Running([sys.executable, "-m", "mlaunch", str(LAUNCH), "--print"], env=env, cwd=str(REPO))
    assert run.finish(timeout=20) == 0, run.text
    out = run.text
    assert "error" not in out.lower().replace("stderr", "")
    # The static transforms run as the stand-in where tf2_msgs is installed (scripts/setup
    # builds it), and are dropped with a warning where it is not.
    tf_runs = HAVE_TF2_MSGS
    assert f"{7 if tf_runs else 5} process(es) at start" in out
    for expected in (
        "(stand-in for gzserver)",
        "spawn_entity.py-2   (stand-in for gazebo_ros/spawn_entity.py)",
        "joint_state_publisher-3   (stand-in for joint_state_publisher/joint_state_publisher)",
        "robot_state_publisher-4   (stand-in for robot_state_publisher/robot_state_publisher)",
        f"rviz2-{7 if tf_runs else 5}   (stand-in for rviz2/rviz2)",
        *(
            ["static_transform_publisher-5   (stand-in for tf2_ros/static_transform_publisher)"]
            if tf_runs
            else []
        ),
        "-topic robot_description -entity smartcar",
        "robot_description = <string",
        "publish_frequency = 20.0",
        "-d /work/main/robots/smartcar_description/urdf.rviz".replace("/work/main", str(REPO)),
    ):
        assert expected in out, expected
    for line, what in (
        (18, "arbotix_python arbotix_driver (the ArbotiX diff-drive controller) has no ROS 2"),
        (23, "use_gui: ROS 2's joint_state_publisher has no GUI"),
        *(
            []
            if tf_runs
            else [
                (31, "the static transform base_link -> left_front_link is not published"),
                (32, "the static transform base_link -> right_front_link is not published"),
            ]
        ),
        (34, "is a ROS 1 RViz config"),
    ):
        prefix = f"warning: launches/smartcar_display.launch:{line}: "
        assert re.search(re.escape(prefix) + ".*" + re.escape(what), out), (line, what)


def test_plan_has_the_expected_processes_and_parameters(tmp_path: Path) -> None:
    plan = plan_of(str(LAUNCH), temp=tmp_path)
    sim, spawn, jsp, rsp, left_tf, right_tf, rviz = plan.processes()
    assert left_tf.standin == right_tf.standin == "tf2_ros/static_transform_publisher"
    assert sim.standin == "gzserver" and sim.output == "screen"
    start = spawn.argv.index("-topic")
    assert spawn.argv[start : start + 4] == ("-topic", "robot_description", "-entity", "smartcar")
    assert jsp.node is not None and jsp.node.executable == "joint_state_publisher"
    assert rsp.node is not None and rsp.node.executable == "robot_state_publisher"
    assert rviz.node is not None and rviz.node.package == "rviz2"
    for node in (spawn, jsp, rsp, rviz):
        assert "use_sim_time:=False" in node.argv  # /use_sim_time: a global on every node
    own = params(rsp)
    assert own["publish_frequency"] == 20.0
    assert own["robot_description"].startswith("<?xml")
    assert '<robot name="smartcar">' in own["robot_description"]
    assert params(jsp) == {} and params(rviz) == {}  # robot_description went to rsp only
    gui = plan_of(str(LAUNCH), {"gui": "true"}, temp=tmp_path / "gui")
    jsp_gui = gui.processes()[2]
    assert jsp_gui.node is not None and jsp_gui.node.package == "joint_state_publisher_gui"


@pytest.mark.parametrize("gui", ["false", "true"])
def test_the_committed_conversion_resolves_to_the_same_plan(tmp_path: Path, gui: str) -> None:
    ros1 = summarize(plan_of(str(LAUNCH), {"gui": gui}, temp=tmp_path / "ros1"))
    ros2 = summarize(plan_of(str(TWIN), {"gui": gui}, temp=tmp_path / "ros2"))
    assert ros2 == ros1


def test_the_committed_conversion_is_what_convert_writes_today() -> None:
    assert convert.convert(str(LAUNCH), "py", str(TWIN)) == TWIN.read_text()


@pytest.mark.parametrize("fmt", ["yaml", "xml"])
def test_yaml_and_xml_conversions_resolve_to_the_same_plan(tmp_path: Path, fmt: str) -> None:
    out = tmp_path / f"smartcar_display.launch.{fmt}"
    assert mlaunch_main(["convert", str(LAUNCH), "--to", fmt, "-o", str(out)]) == 0
    for gui in ("false", "true"):
        ros1 = summarize(plan_of(str(LAUNCH), {"gui": gui}, temp=tmp_path / f"a{gui}"))
        ros2 = summarize(plan_of(str(out), {"gui": gui}, temp=tmp_path / f"b{gui}"))
        assert ros2 == ros1


@pytest.mark.slow
def test_the_smartcar_runs_spawns_and_stops_clean(ros_env: dict[str, str]) -> None:
    env = clean_env(**ros_env, ROS_LOG_DIR="/tmp/mlaunch-test-smartcar-logs")
    env.pop("AMENT_PREFIX_PATH", None)
    run = Running([sys.executable, "-m", "mlaunch", str(LAUNCH)], env=env, cwd=str(REPO))
    try:
        run.wait_for(r"spawned model 'smartcar' .*diff drive /cmd_vel -> /odom", timeout=25)
        run.wait_for(r"spawn_entity\.py: spawned entity 'smartcar'", timeout=10)
        run.wait_for(r"\[robot_state_publisher\]: got segment head", timeout=10)
        run.signal(signal.SIGINT)
        code = run.finish(timeout=20)
    finally:
        if run.proc.poll() is None:
            os.killpg(run.proc.pid, signal.SIGKILL)
            run.proc.wait()
    assert code in (0, 130), run.text
    assert "process has died" not in run.text
