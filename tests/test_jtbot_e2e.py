"""The main job, end to end: `mlaunch launches/jtbot_sim.launch.py` on the built-in defaults.

Every process comes up, /clock advances, every node runs with use_sim_time true, a Twist on
/cmd_vel moves /odom and changes /scan, the viewer serves the live state, and Ctrl-C ends
everything, leaving no process behind.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from typing import Any

import pytest
from conftest import requires_rclpy
from procutil import REPO, Running, clean_env, mlaunch, pid_alive, wait_until
from test_interfaces import HAVE_TF2_MSGS

pytestmark = [requires_rclpy, pytest.mark.slow]

EXPECTED_NODES = ["/gazebo", "/robot_state_publisher", "/rviz2"]


def descendants_of(pid: int) -> list[int]:
    import psutil

    try:
        return [p.pid for p in psutil.Process(pid).children(recursive=True)]
    except psutil.NoSuchProcess:
        return []


def run_probe(env: dict[str, str], nodes: list[str]) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, str(Path(__file__).parent / "e2e_probe.py"), ",".join(nodes), "40"],
        capture_output=True,
        text=True,
        env=env,
        timeout=90,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])  # type: ignore[no-any-return]


def check_tf_tree(env: dict[str, str]) -> None:
    """Every jtbot link is reachable from odom: odom -> base_link from the simulator's diff
    drive, moving wheels from robot_state_publisher on /tf, fixed joints on /tf_static."""
    done = subprocess.run(
        [sys.executable, str(Path(__file__).parent / "tf_tree_probe.py"), "odom", "30"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    tree = json.loads(done.stdout.strip().splitlines()[-1])
    parents, topics = tree["parents"], tree["topics"]
    assert parents["base_footprint"] == "odom" and topics["base_footprint"] == "/tf"
    assert topics["left_wheel_link"] == "/tf" and topics["camera_depth_frame"] == "/tf_static"
    assert parents["camera_depth_frame"] == "camera_link"


@pytest.mark.serial  # how long Ctrl-C takes
def test_jtbot_sim_end_to_end(ros_env: dict[str, str], tmp_path: Path) -> None:
    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    env["MLAUNCH_VIEWER_PORT"] = "0"
    run = Running(
        mlaunch(str(REPO / "launches" / "jtbot_sim.launch.py")), env=env, cwd=str(tmp_path)
    )
    try:
        url = run.wait_for(r"viewer: open (http://127\.0\.0\.1:\d+/)", timeout=60).group(1)
        run.wait_for(r"\[spawn_entity\.py-3\]: process has finished cleanly", timeout=60)
        children = descendants_of(run.proc.pid)
        assert len(children) >= 3, run.text
        result = run_probe(env, EXPECTED_NODES)
        assert set(EXPECTED_NODES) <= set(result["nodes"]), result
        assert result["use_sim_time"] == {n: True for n in EXPECTED_NODES}, result
        assert result["clock_advanced"], result
        assert result["odom_moved"] > 0.2, result  # type: ignore[operator]
        assert result["scan_changed"] > 0.05 and result["scan_samples"] == 360, result  # type: ignore[operator]
        with urllib.request.urlopen(url + "state.json", timeout=5) as response:
            state = json.loads(response.read())
        assert state, "the viewer serves no state"
        if HAVE_TF2_MSGS:
            check_tf_tree(env)
        # Ctrl-C: everything ends, nothing is left behind.
        everything = descendants_of(run.proc.pid)
        sent = time.monotonic()
        run.signal(signal.SIGINT)
        code = run.finish(timeout=15)
        took = time.monotonic() - sent
    finally:
        run.kill()
    assert code == 130, run.text[-3000:]
    assert wait_until(lambda: not any(pid_alive(p) for p in everything), 2.0)
    # Typically about 0.7 s here (benchmarks measure it); the bound only catches a hang or a
    # ladder step (5 s) being needed, with room for a loaded CI machine.
    print(f"shutdown took {took:.2f} s for {len(everything)} processes")
    assert took < 4.5, f"Ctrl-C took {took:.2f} s: something needed the SIGTERM step"
    assert "Traceback" not in run.text, run.text[-3000:]


def test_seed_launch_file_runs_unmodified(ros_env: dict[str, str], tmp_path: Path) -> None:
    """The seed's own file (import launch, launch_ros, xacro directly) runs and spawns the robot."""
    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    run = Running(
        mlaunch(str(REPO / "launches" / "jtbot_seed.launch.py")), env=env, cwd=str(tmp_path)
    )
    try:
        run.wait_for(r"gazebo: not installed, using mlaunch's stand-in", timeout=30)
        run.wait_for(r"\[spawn_entity\.py-2\]: process has finished cleanly", timeout=60)
        run.wait_for(r"viewer: open http://127\.0\.0\.1:\d+/", timeout=30)
        run.signal(signal.SIGINT)
        assert run.finish(timeout=15) == 130
    finally:
        run.kill()
    assert "Traceback" not in run.text, run.text[-3000:]


def test_jtbot_sim_passes_mlaunch_test(ros_env: dict[str, str], tmp_path: Path) -> None:
    """The CI smoke launch: `mlaunch test` on jtbot_sim, with its sensors as expectations."""
    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    junit = tmp_path / "jtbot.xml"
    done = subprocess.run(
        mlaunch(
            "test",
            str(REPO / "launches" / "jtbot_sim.launch.py"),
            "--allow-exit",
            "spawn_entity.py",
            "--expect-topic",
            "/scan:4",
            "--expect-topic",
            "/odom",
            "--expect-topic",
            "/imu",
            # The image, not the 3.7 MB point cloud at 30 Hz: that would slow the simulator on
            # a loaded CI machine (test_standin_camera checks the cloud's content).
            "--expect-topic",
            "/depth_camera/depth/image_raw",
            *(("--expect-topic", "/tf", "--expect-topic", "/tf_static") if HAVE_TF2_MSGS else ()),
            "--expect-output",
            "spawn_entity.py:spawned entity 'jtbot'",
            "--hold",
            "1",
            "--junit",
            str(junit),
        ),
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    report = junit.read_text()
    assert 'failures="0"' in report and "/scan" in report and "/clock" in report


def test_jtbot_display_without_simulator(ros_env: dict[str, str], tmp_path: Path) -> None:
    """State publisher, joint state publisher and viewer: the description and joints flow."""
    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    done = subprocess.run(
        mlaunch(
            "test",
            str(REPO / "launches" / "jtbot_display.launch.py"),
            "--expect-topic",
            "/joint_states",
            "--expect-topic",
            "/robot_description",
            "--expect-node",
            "/robot_state_publisher",
            "--expect-output",
            "rviz2:viewer: open http://127.0.0.1:",
        ),
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "stand-in" in done.stdout
