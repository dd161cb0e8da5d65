"""Restarting the viewer stand-in keeps its port, so the open tab lives on (issue 27, item 15)."""

from __future__ import annotations

import json
import re
import signal
import sys
import urllib.request
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import Running, mlaunch, run_mlaunch

LAUNCH = """from launch import LaunchDescription
from launch.actions import TimerAction
from launch_ros.actions import Node
def generate_launch_description():
    viewer = Node(package="rviz2", executable="rviz2", output="screen")
    return LaunchDescription([{}])
"""
OPEN = r"viewer: open http://127\.0\.0\.1:(\d+)/"


def state_of(port: str) -> dict[str, object]:
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/state.json", timeout=5) as reply:
        return dict(json.loads(reply.read()))


@requires_rclpy
@pytest.mark.timeout(90)
@pytest.mark.parametrize("started", ["viewer", "TimerAction(period=0.1, actions=[viewer])"])
def test_a_restarted_viewer_listens_on_the_same_port(
    ros_env: dict[str, str], tmp_path: Path, started: str
) -> None:
    path = tmp_path / "view.launch.py"
    path.write_text(LAUNCH.format(started))
    env = {**ros_env, "ROS_LOG_DIR": str(tmp_path / "logs")}
    env.pop("MLAUNCH_VIEWER_PORT", None)
    run = Running(mlaunch(str(path)), env=env, cwd=str(tmp_path))
    try:
        first = run.wait_for(OPEN, 30).group(1)
        assert "robot" in state_of(first)
        done = run_mlaunch("ctl", "restart", "rviz2-1", env=env, timeout=30)
        assert done.returncode == 0, done.stdout + done.stderr
        run.wait_for(rf"{OPEN}[\s\S]*{OPEN}", 30)
        ports = re.findall(OPEN, run.text)
        assert ports == [first, first], run.text  # before: a new random port each start
        assert "robot" in state_of(first)
        run.signal(signal.SIGINT)
        assert run.finish(30) == 130
    finally:
        if run.proc.poll() is None:
            run.kill()


def test_a_simulator_restart_is_said_and_the_robot_that_is_gone_is_not_drawn() -> None:
    from test_viewer import URDF
    from test_viewer_world import JT_WORLD

    from mlaunch.standins.viewer import DisplayConfig, ViewerState
    from mlaunch.standins.world import load_world
    from mlaunch.standins.world_topic import world_message

    world = load_world(JT_WORLD)
    state = ViewerState(DisplayConfig())
    state.set_description(URDF, now=0.0)
    state.set_world(world_message(world, [], run="first"), now=0.0)
    state.set_odom("odom", "base_link", (1.0, 2.0, 0.0), now=1.0)
    live = state.snapshot(1.5)
    assert live["simulator"] == {"restarts": 0, "robot": "live"} and live["robot"] is not None
    assert not any("odometry" in w or "simulator" in w for w in live["warnings"])
    # The simulator dies: the robot is drawn where it was, and the page says so.
    lost = state.snapshot(5.0)
    assert lost["simulator"]["robot"] == "lost" and lost["pose"]["x"] == 1.0
    assert "no odometry on odom for 4 s: the robot is drawn where it was" in lost["warnings"]
    # It comes back without the robot (the spawner ran once): before, the old robot stayed.
    state.set_world(world_message(world, [], run="second"), now=6.0)
    gone = state.snapshot(6.5)
    assert gone["simulator"] == {"restarts": 1, "robot": "gone"}
    assert gone["robot"] is None and gone["pose"] is None and gone["trail"] == []
    assert any("the simulator restarted and the robot is not in it" in w for w in gone["warnings"])
    # The robot is spawned again (the same simulator republishes its world): the new state.
    state.set_world(world_message(world, [], run="second"), now=7.0)
    state.set_odom("odom", "base_link", (0.0, 0.0, 0.0), now=7.5)
    back = state.snapshot(8.0)
    assert back["simulator"] == {"restarts": 1, "robot": "live"}
    assert back["robot"] is not None and back["pose"]["x"] == 0.0
    assert "the simulator restarted: showing the new state" in back["warnings"]


@requires_rclpy
@pytest.mark.timeout(90)
def test_the_viewer_sees_a_real_simulator_restart(ros_env: dict[str, str], tmp_path: Path) -> None:
    from procutil import wait_for
    from test_viewer import Child, fetch_state
    from test_viewer_world import JT_WORLD

    env = {**ros_env, "MLAUNCH_VIEWER_PORT": "0"}
    sim_argv = [sys.executable, "-m", "mlaunch.standins.sim", str(JT_WORLD)]
    sim = Child(sim_argv, env, tmp_path, "sim")
    viewer = Child([sys.executable, "-m", "mlaunch.standins.viewer"], env, tmp_path, "viewer")
    again = None
    try:
        url = wait_for(
            lambda: re.search(r"viewer: open (\S+)", viewer.stdout()), 20, "the viewer's address"
        ).group(1)
        wait_for(lambda: fetch_state(url)["world"], 20, "the first simulator's world")
        assert fetch_state(url)["simulator"]["restarts"] == 0
        sim.stop()
        again = Child(sim_argv, env, tmp_path, "sim2")  # a new start of the same simulator
        state = wait_for(
            lambda: (s := fetch_state(url))["simulator"]["restarts"] == 1 and s, 30, "a restart"
        )
        assert "the simulator restarted: showing the new state" in state["warnings"]
        assert state["world"]["name"] == "jt_world"
    finally:
        for child in (viewer, sim, again):
            if child is not None:
                child.stop()
