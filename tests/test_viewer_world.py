"""The viewer draws the simulator's world: the document the simulator publishes, the viewer's
JSON, and the page in headless chromium (test_viewer.py's browser helper)."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import pytest
from conftest import REPO, requires_rclpy
from procutil import wait_for
from test_viewer import CHROMIUM, Child, fetch_state, load_page

from mlaunch.standins.diffdrive import Pose2D
from mlaunch.standins.shapes import Disc, Polygon
from mlaunch.standins.simulation import SimRobot
from mlaunch.standins.viewer import DisplayConfig, ViewerState
from mlaunch.standins.world import World, load_world
from mlaunch.standins.world_topic import WorldPicture, shape_json, world_message

JT_WORLD = REPO / "robots" / "jtbot_description" / "world" / "jt.world"


def robot(frame: str, source: int, spawn: Pose2D) -> SimRobot:
    """Just what the world document reads of a spawned robot: its drive's odometry settings."""
    drive = SimpleNamespace(
        publish_odom=True, publish_odom_tf=False, odometry_frame=frame, odometry_source=source
    )
    return cast(SimRobot, SimpleNamespace(spec=SimpleNamespace(drive=drive), spawn=spawn))


def test_the_world_reaches_the_viewer_as_the_simulator_loaded_it() -> None:
    world = load_world(JT_WORLD)
    picture = WorldPicture()
    picture.set(world_message(world, [robot("odom", 1, Pose2D(1.0, 2.0, 0.5))]))
    seen = picture.in_frame("odom")
    assert seen is not None and seen["name"] == "jt_world"
    # World odometry starts at the world's origin: the shapes are the simulator's, unmoved.
    assert seen["shapes"] == [shape_json(s) for s in world.shapes]
    assert {s["model"] for s in seen["shapes"]} >= {"wall_east", "wall_west"}
    east = next(s for s in seen["shapes"] if s["model"] == "wall_east")
    assert sorted(east["points"]) == [[3.95, -4.05], [3.95, 4.05], [4.05, -4.05], [4.05, 4.05]]


def test_encoder_odometry_sees_the_world_from_where_the_robot_was_spawned() -> None:
    world = World(
        name="two",
        shapes=[
            Disc("pillar", 3.0, 2.0, 0.25, 0.0, 1.0),
            Polygon("block", ((2.0, 0.0), (3.0, 0.0), (3.0, 1.0), (2.0, 1.0)), 0.0, 0.5),
        ],
    )
    spawn = Pose2D(2.0, 2.0, math.pi / 2)  # facing +y: the world's +x is the frame's -y
    picture = WorldPicture()
    picture.set(world_message(world, [robot("r1/odom", 0, spawn)]))
    seen = picture.in_frame("r1/odom")
    assert seen is not None
    pillar, block = seen["shapes"]
    assert (pillar["x"], pillar["y"], pillar["r"]) == (pytest.approx(0.0), -1.0, 0.25)
    assert [pytest.approx(p, abs=1e-9) for p in block["points"][0]] == [-2.0, 0.0]
    # A frame the simulator does not know is the world's own (as Gazebo's world odometry).
    other = picture.in_frame("map")
    assert other is not None and other["shapes"][0]["x"] == 3.0


def test_viewer_state_serves_the_world_and_reports_a_broken_one() -> None:
    state = ViewerState(DisplayConfig())
    assert state.snapshot(now=0.0)["world"] is None
    world = load_world(JT_WORLD)
    state.set_world(world_message(world, []), now=1.0)
    snap = state.snapshot(now=1.5)
    assert snap["world"]["frame"] == "odom"
    assert len(snap["world"]["shapes"]) == len(world.shapes)
    assert snap["topics"]["world"] == {"topic": "/mlaunch_sim/world", "count": 1, "age": 0.5}
    state.set_world('{"shapes": [{"type": "star"}]}', now=2.0)
    snap = state.snapshot(now=2.0)
    assert len(snap["world"]["shapes"]) == len(world.shapes)  # the last good world stays
    assert any("world from /mlaunch_sim/world not understood" in w for w in snap["warnings"])


@pytest.fixture
def sim_and_viewer(ros_env: dict[str, str], tmp_path: Path) -> Iterator[str]:
    """The simulator stand-in on jt.world and the viewer; yields the viewer's address."""
    env = {**ros_env, "MLAUNCH_VIEWER_PORT": "0"}
    sim = Child([sys.executable, "-m", "mlaunch.standins.sim", str(JT_WORLD)], env, tmp_path, "sim")
    viewer = Child([sys.executable, "-m", "mlaunch.standins.viewer"], env, tmp_path, "viewer")
    try:

        def listening() -> str | None:
            for child in (sim, viewer):
                if child.popen.poll() is not None:
                    raise AssertionError(f"exited: {child.stderr()[-2000:]}")
            text = viewer.stdout()
            return text.split("viewer: open ", 1)[1].split()[0] if "viewer: open " in text else None

        yield wait_for(listening, 20, "the viewer's address")
    finally:
        viewer.stop()
        sim.stop()


def world_of(url: str) -> dict[str, Any] | None:
    world: dict[str, Any] | None = fetch_state(url)["world"]
    return world


@requires_rclpy
@pytest.mark.timeout(60)
def test_the_viewer_serves_the_running_simulators_world(sim_and_viewer: str) -> None:
    world = wait_for(lambda: world_of(sim_and_viewer), 20, "the world in the viewer's JSON")
    expected = json.loads(world_message(load_world(JT_WORLD), []))["shapes"]
    assert world["name"] == "jt_world"
    assert world["shapes"] == expected


def _colour(text: str) -> tuple[int, ...]:
    return tuple(int(v) for v in text.split(","))


@requires_rclpy
@pytest.mark.timeout(90)
@pytest.mark.skipif(not Path(CHROMIUM).exists(), reason=f"{CHROMIUM} not installed (apt chromium)")
def test_the_page_draws_the_walls(sim_and_viewer: str, tmp_path: Path) -> None:
    url = sim_and_viewer
    world = wait_for(lambda: world_of(url), 20, "the world in the viewer's JSON")
    # Inside the east wall (x 3.95..4.05), and in the middle of the empty room.
    probe = "4.0,1.0;1.5,1.5"
    page = load_page(f"{url}?follow=0&scale=60&probe={probe}", tmp_path / "profile")
    assert page["world-shapes"] == str(len(world["shapes"])), page
    wall, room = (_colour(c) for c in page["probe"].split(";"))
    assert wall == (91, 100, 116) or min(wall) > 85, page  # the wall fill (#5b6474) or its edge
    assert max(room) < 80, page  # background or grid
