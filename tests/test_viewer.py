"""The rviz2 stand-in: config and state logic, its JSON endpoint, and the page in a real browser.

The process tests run the viewer and a fake robot (a child publishing /robot_description,
odometry and a laser scan, moved by lines on its stdin) in a private ROS domain; the browser test
loads the page in headless Debian chromium and reads what the page reports it drew.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from browser import CHROMIUM, FLAGS
from conftest import requires_rclpy
from procutil import wait_for

from mlaunch.standins.viewer import (
    DisplayConfig,
    ViewerError,
    ViewerState,
    config_from_data,
    parse_args,
    read_display_config,
    viewer_port,
)

URDF = """<?xml version="1.0"?>
<robot name="viewbot">
  <link name="base_footprint"/>
  <link name="base_link"><visual><geometry><box size="0.4 0.3 0.1"/></geometry></visual></link>
  <link name="laser_frame">
    <visual><geometry><cylinder radius="0.04" length="0.04"/></geometry></visual>
  </link>
  <joint name="base_joint" type="fixed">
    <parent link="base_footprint"/><child link="base_link"/><origin xyz="0 0 0.05"/>
  </joint>
  <joint name="laser_joint" type="fixed">
    <parent link="base_link"/><child link="laser_frame"/>
    <origin xyz="0.1 0 0.1" rpy="0 0 1.5707963267948966"/>
  </joint>
</robot>
"""

RVIZ_CONFIG = """
Panels: []
Visualization Manager:
  Class: ""
  Displays:
    - Class: rviz_default_plugins/Grid
      Enabled: true
      Name: Grid
    - Class: rviz_default_plugins/LaserScan
      Enabled: false
      Name: disabled scan
      Topic: {Value: /ignored/scan}
    - Class: rviz_common/Group
      Enabled: true
      Name: sensors
      Displays:
        - Class: rviz_default_plugins/LaserScan
          Enabled: true
          Name: LaserScan
          Topic:
            Value: /front/scan
            Depth: 5
            Reliability Policy: Best Effort
    - Class: rviz_default_plugins/Odometry
      Enabled: true
      Name: Odometry
      Topic:
        Value: /wheel/odom
    - Class: rviz_default_plugins/RobotModel
      Enabled: true
      Description Source: Topic
      Description Topic:
        Value: /robot_description
  Global Options:
    Fixed Frame: odom
"""

# ---------------------------------------------------------------- pure: config and state


def test_config_takes_enabled_displays_inside_groups() -> None:
    import yaml

    config = config_from_data(yaml.safe_load(RVIZ_CONFIG))
    assert config == DisplayConfig(
        fixed_frame="odom",
        scan_topic="/front/scan",
        odom_topic="/wheel/odom",
        description_topic="/robot_description",
    )


def test_config_old_style_topic_strings_and_defaults() -> None:
    data = {
        "Visualization Manager": {
            "Displays": [{"Class": "rviz/LaserScan", "Topic": "base_scan"}],
            "Global Options": {"Fixed Frame": "map"},
        }
    }
    config = config_from_data(data)
    assert (config.fixed_frame, config.scan_topic, config.odom_topic) == (
        "map",
        "base_scan",
        "odom",
    )


def test_missing_or_broken_config_is_a_warning(tmp_path: Path) -> None:
    missing = read_display_config(str(tmp_path / "nope.rviz"))
    assert missing.warnings == (
        f"display config {str(tmp_path / 'nope.rviz')!r} not loaded: No such file or directory",
    )
    assert missing.scan_topic == "scan"
    broken = tmp_path / "broken.rviz"
    broken.write_text("Visualization Manager: [unclosed\n")
    assert "is not valid YAML" in read_display_config(str(broken)).warnings[0]


def test_rviz2_command_line() -> None:
    options = parse_args(["-d", "a.rviz", "-f", "base_link", "--splash-screen", "s.png", "-l"])
    assert (options.display_config, options.fixed_frame, options.ogre_log) == (
        "a.rviz",
        "base_link",
        True,
    )
    assert parse_args(["--display-config", "b.rviz", "-s"]).display_config == "b.rviz"
    with pytest.raises(ViewerError, match="unknown rviz2 option '--bogus'"):
        parse_args(["--bogus"])


def test_viewer_port_from_environment() -> None:
    assert viewer_port({}) == 0
    assert viewer_port({"MLAUNCH_VIEWER_PORT": "8080"}) == 8080
    expected = "MLAUNCH_VIEWER_PORT='http' is not a port; use 0..65535"
    with pytest.raises(ViewerError, match=re.escape(expected)):
        viewer_port({"MLAUNCH_VIEWER_PORT": "http"})
    with pytest.raises(ViewerError, match="'70000'"):
        viewer_port({"MLAUNCH_VIEWER_PORT": "70000"})


def test_state_places_scan_with_odom_pose_and_laser_mount() -> None:
    state = ViewerState(DisplayConfig())
    state.set_description(URDF, now=0.0)
    state.set_odom("odom", "base_footprint", (1.0, 2.0, math.pi / 2), now=0.0)
    # two rays of 1 m: straight ahead of the laser, and one below range_min (dropped)
    state.set_scan("laser_frame", 0.0, 0.1, [1.0, 0.01, math.inf], (0.05, 10.0), now=0.5)
    snap = state.snapshot(now=1.0)
    # laser 0.1 m ahead of the base and turned 90 degrees; the robot faces +y: so the laser sits
    # at (1, 2.1) facing -x, and its forward ray ends 1 m further along -x.
    ((x, y),) = snap["scan"]["points"]
    assert (x, y) == (pytest.approx(0.0), pytest.approx(2.1))
    assert snap["pose"] == {"x": 1.0, "y": 2.0, "yaw": pytest.approx(math.pi / 2)}
    assert snap["robot"]["name"] == "viewbot"
    assert {s["link"] for s in snap["robot"]["shapes"]} == {"base_link", "laser_frame"}
    assert snap["topics"]["scan"] == {"topic": "scan", "count": 1, "age": 0.5}
    assert snap["robot_centric"] is False


def test_state_reports_unknown_laser_frame_and_bad_urdf() -> None:
    state = ViewerState(DisplayConfig(fixed_frame="base_link"))
    state.set_description(URDF, now=0.0)
    state.set_scan("elsewhere", 0.0, 0.1, [1.0], (0.0, 5.0), now=0.0)
    snap = state.snapshot(now=0.0)
    assert snap["scan"]["points"] == [[1.0, 0.0]]
    assert "laser frame 'elsewhere' is not a link of 'viewbot'" in snap["warnings"][0]
    assert snap["robot_centric"] is True  # fixed frame on the robot
    state.set_description("<robot name='x'><link name='a'/><link name='b'/></robot>", now=0.0)
    snap = state.snapshot(now=0.0)
    assert snap["robot"] is None and "2 root links" in snap["robot_error"]


def test_tf_places_the_scan_where_odometry_and_the_urdf_cannot() -> None:
    """A laser on a frame the URDF lacks, mounted by a static transform: TF puts it in place."""
    state = ViewerState(DisplayConfig())
    state.set_description(URDF, now=0.0)
    state.set_odom("odom", "base_footprint", (1.0, 0.0, 0.0), now=0.0)
    state.set_transforms(
        [
            ("odom", "base_footprint", (1.0, 0.0, 0.0)),
            ("base_footprint", "base_link", (0.0, 0.0, 0.0)),
            ("base_link", "rear_laser", (-0.5, 0.0, math.pi)),  # looks backwards
        ],
        now=0.0,
    )
    state.set_scan("rear_laser", 0.0, 0.1, [2.0], (0.05, 10.0), now=0.0)
    snap = state.snapshot(now=0.0)
    ((x, y),) = snap["scan"]["points"]
    assert (x, y) == (pytest.approx(-1.5), pytest.approx(0.0))  # 1 - 0.5 - 2, behind the robot
    assert not snap["warnings"]  # TF knew the frame: no "not a link" warning
    assert {"odom", "base_footprint", "base_link", "rear_laser"} <= set(snap["frames"])


def test_tf_places_the_robot_without_odometry() -> None:
    state = ViewerState(DisplayConfig())
    state.set_description(URDF, now=0.0)
    state.set_transforms([("odom", "base_footprint", (0.5, -1.0, 0.25))], now=0.0)
    snap = state.snapshot(now=0.0)
    assert snap["pose"] == {"x": 0.5, "y": -1.0, "yaw": 0.25}


def test_a_page_is_open_while_it_polls() -> None:
    """The depth feed runs only while a page polls: closed after PAGE_IDLE_S without a poll."""
    from mlaunch.standins.viewer import PAGE_IDLE_S

    state = ViewerState(DisplayConfig(depth_topic="/cam/depth/image_raw"))
    assert not state.page_open(now=100.0)
    state.note_poll(now=100.0)
    assert state.page_open(now=100.0 + PAGE_IDLE_S - 0.1)
    assert not state.page_open(now=100.0 + PAGE_IDLE_S + 0.1)


def test_depth_image_becomes_a_small_grey_png() -> None:
    import struct
    import zlib

    import numpy as np

    state = ViewerState(DisplayConfig(depth_topic="/cam/depth/image_raw"))
    depth = np.full((480, 640), 2.0, dtype="<f4")
    depth[:, :320] = np.inf  # the left half sees nothing
    state.set_depth(640, 480, "32FC1", depth.tobytes(), 4.0, now=0.0)
    snap = state.snapshot(now=0.0)
    assert snap["depth"] == {
        "seq": 1,
        "topic": "/cam/depth/image_raw",
        "size": [640, 480],
        "encoding": "32FC1",
    }
    png = state.depth_png()
    assert png is not None and png.startswith(b"\x89PNG\r\n\x1a\n")
    width, height = struct.unpack(">II", png[16:24])
    assert (width, height) == (160, 120)  # a quarter of the camera's size
    idat = png.index(b"IDAT")
    (length,) = struct.unpack(">I", png[idat - 4 : idat])
    rows = zlib.decompress(png[idat + 4 : idat + 4 + length])
    first = rows[1 : 1 + width]  # after the filter byte
    assert set(first[:80]) == {0} and set(first[80:]) == {127}  # no reading black; 2 of 4 m


# ---------------------------------------------------------------- processes

FAKE_ROBOT = textwrap.dedent(
    r"""
    import math, sys, threading
    import rclpy
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
    from std_msgs.msg import String
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import LaserScan

    urdf, odom_topic, scan_topic = sys.argv[1:4]
    rclpy.init()
    node = Node("fake_robot")
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_publisher(String, "/robot_description", latched).publish(String(data=urdf))
    odom = node.create_publisher(Odometry, odom_topic, 10)  # reliable, as diff drive plugins do
    scan = node.create_publisher(LaserScan, scan_topic, qos_profile_sensor_data)
    pose = [None]

    def read_commands():
        for line in sys.stdin:  # "x y yaw": publish at that pose from now on
            pose[0] = [float(v) for v in line.split()]

    def tick():
        if pose[0] is None:
            return
        x, y, yaw = pose[0]
        m = Odometry()
        m.header.frame_id, m.child_frame_id = "odom", "base_footprint"
        m.pose.pose.position.x, m.pose.pose.position.y = x, y
        m.pose.pose.orientation.z, m.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        odom.publish(m)
        s = LaserScan()
        s.header.frame_id = "laser_frame"
        s.angle_min, s.angle_increment = 0.0, 2 * math.pi / 8
        s.angle_max = s.angle_increment * 7
        s.range_min, s.range_max = 0.1, 5.0
        s.ranges = [1.0] * 8
        scan.publish(s)

    threading.Thread(target=read_commands, daemon=True).start()
    node.create_timer(0.05, tick)
    rclpy.spin(node)
    """
)


class Child:
    """A child process with its output in files, stopped (SIGTERM, then SIGKILL) at the end."""

    def __init__(self, argv: list[str], env: dict[str, str], workdir: Path, name: str) -> None:
        self.out_path, self.err_path = workdir / f"{name}.out", workdir / f"{name}.err"
        with open(self.out_path, "wb") as out, open(self.err_path, "wb") as err:
            self.popen = subprocess.Popen(
                argv, env=env, stdin=subprocess.PIPE, stdout=out, stderr=err, text=True
            )

    def stdout(self) -> str:
        return self.out_path.read_text(errors="replace")

    def stderr(self) -> str:
        return self.err_path.read_text(errors="replace")

    def send(self, line: str) -> None:
        assert self.popen.stdin is not None
        self.popen.stdin.write(line + "\n")
        self.popen.stdin.flush()

    def stop(self) -> None:
        if self.popen.poll() is None:
            self.popen.terminate()
            try:
                self.popen.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait()
        if self.popen.stdin is not None:
            self.popen.stdin.close()


def fetch_state(url: str) -> dict[str, Any]:
    with urllib.request.urlopen(url + "state.json", timeout=5) as reply:
        return json.loads(reply.read())


@pytest.fixture
def scene(ros_env: dict[str, str], tmp_path: Path) -> Iterator[tuple[str, Child, Child]]:
    """A running viewer (config from RVIZ_CONFIG) and fake robot; yields (url, viewer, robot)."""
    config = tmp_path / "view.rviz"
    config.write_text(RVIZ_CONFIG)
    env = {**ros_env, "MLAUNCH_VIEWER_PORT": "0"}
    children: list[Child] = []
    try:
        robot_argv = [sys.executable, "-c", FAKE_ROBOT, URDF, "/wheel/odom", "/front/scan"]
        children.append(Child(robot_argv, env, tmp_path, "robot"))
        viewer_argv = [sys.executable, "-m", "mlaunch.standins.viewer", "-d", str(config)]
        viewer_argv += ["--splash-screen", "none.png", "--ros-args", "-r", "__node:=rviz2"]
        children.append(Child(viewer_argv, env, tmp_path, "viewer"))
        viewer = children[-1]

        def listening() -> str | None:
            if viewer.popen.poll() is not None:
                raise AssertionError(f"viewer exited: {viewer.stderr()[-2000:]}")
            match = re.search(r"^viewer: open (http://127\.0\.0\.1:\d+/)$", viewer.stdout(), re.M)
            return match.group(1) if match else None

        url = wait_for(listening, 15, "the viewer's 'open' line")
        yield url, viewer, children[0]
    finally:
        for child in children:
            child.stop()


def move_to(robot: Child, url: str, pose: tuple[float, float, float]) -> dict[str, Any]:
    """Put the fake robot at ``pose`` and wait until the viewer's JSON shows it with a scan."""
    robot.send(" ".join(map(str, pose)))

    def arrived() -> dict[str, Any] | None:
        state = fetch_state(url)
        p = state["pose"]
        at_pose = p and math.dist((p["x"], p["y"]), pose[:2]) < 1e-6
        # the scan must have been taken at this pose: its points ring the laser 1 m away
        laser = (pose[0] + 0.1 * math.cos(pose[2]), pose[1] + 0.1 * math.sin(pose[2]))
        points = state["scan"]["points"]
        ringed = points and all(abs(math.dist(q, laser) - 1.0) < 1e-3 for q in points)
        return state if at_pose and ringed and state["robot"] else None

    return wait_for(arrived, 20, f"the viewer to show the robot at {pose}")


@requires_rclpy
@pytest.mark.timeout(60)
def test_json_reflects_published_odom_scan_and_description(
    scene: tuple[str, Child, Child],
) -> None:
    url, viewer, robot = scene
    state = move_to(robot, url, (1.0, 2.0, 0.0))
    assert state["fixed_frame"] == "odom"
    assert state["robot"]["name"] == "viewbot"
    assert state["robot"]["root"] == "base_footprint"
    assert state["topics"]["odom"]["topic"] == "/wheel/odom"
    assert state["topics"]["scan"]["topic"] == "/front/scan"
    assert state["topics"]["description"]["count"] == 1
    # laser at (1.1, 2) turned +90 degrees: ray i at angle i*45 degrees leaves along 90 + 45 i
    expected = [
        (
            1.1 + math.cos(math.pi / 2 + i * math.pi / 4),
            2.0 + math.sin(math.pi / 2 + i * math.pi / 4),
        )
        for i in range(8)
    ]
    assert len(state["scan"]["points"]) == 8
    for got, want in zip(state["scan"]["points"], expected, strict=True):
        assert got == [pytest.approx(want[0], abs=1e-3), pytest.approx(want[1], abs=1e-3)]
    state = move_to(robot, url, (-1.5, -0.5, math.pi / 2))
    assert state["trail"][0] == [1.0, 2.0] and state["trail"][-1] == [-1.5, -0.5]
    assert state["pose"]["yaw"] == pytest.approx(math.pi / 2)
    assert "[rviz2]" in viewer.stderr()  # the node took its name from the ROS arguments


def body_point(pose: tuple[float, float, float], dx: float, dy: float) -> tuple[float, float]:
    """A point fixed on the robot (dx, dy in its frame) in the odometry frame."""
    x, y, yaw = pose
    return (
        x + dx * math.cos(yaw) - dy * math.sin(yaw),
        y + dx * math.sin(yaw) + dy * math.cos(yaw),
    )


def load_page(url: str, profile: Path) -> dict[str, str]:
    """Load ``url`` in headless chromium and return #stats's data attributes and the HUD pose."""
    argv = [
        CHROMIUM,
        *FLAGS,
        f"--user-data-dir={profile}",
        "--window-size=1000,800",
        "--virtual-time-budget=3000",
        "--dump-dom",
        url,
    ]
    # Its own session, so a hung browser's helper processes can be killed together.
    proc = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, start_new_session=True
    )
    try:
        dom, _ = proc.communicate(timeout=45)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    stats = re.search(r'<div id="stats"([^>]*)>', dom)
    assert stats, f"no #stats in the page: {dom[:500]}"
    data = dict(re.findall(r'data-([a-z-]+)="([^"]*)"', stats.group(1)))
    pose = re.search(r'<td class="v mono" id="pose">([^<]*)<', dom)
    data["hud-pose"] = pose.group(1) if pose else ""
    return data


def colour(text: str) -> tuple[int, ...]:
    return tuple(int(v) for v in text.split(","))


def bright(rgb: tuple[int, ...]) -> bool:
    return min(rgb) > 140  # the robot body's light grey-blue


def dark(rgb: tuple[int, ...]) -> bool:
    return max(rgb) < 80  # background or faint grid


@requires_rclpy
@pytest.mark.timeout(90)
@pytest.mark.skipif(not Path(CHROMIUM).exists(), reason=f"{CHROMIUM} not installed (apt chromium)")
def test_browser_draws_the_robot_where_odometry_puts_it(
    scene: tuple[str, Child, Child], tmp_path: Path
) -> None:
    url, _, robot = scene
    a, b = (1.0, 2.0, 0.0), (-1.5, -0.5, math.pi / 2)
    # points on the body, off its axes, off the A-B trail line
    # (0.17, 0.05) on B lies outside the body if its yaw were ignored
    on_a, on_b = body_point(a, -0.1, 0.1), body_point(b, 0.17, 0.05)
    probe = ";".join(f"{x:.3f},{y:.3f}" for x, y in (on_a, on_b))
    page = f"{url}?follow=0&scale=100&probe={probe}"
    shutil.rmtree(tmp_path / "profile", ignore_errors=True)

    move_to(robot, url, a)
    first = load_page(page, tmp_path / "profile")
    assert int(first["frame"]) >= 1 and int(first["seq"]) > 0, first
    assert first["scan-points"] == "8"
    at_a, at_b = (colour(c) for c in first["probe"].split(";"))
    assert bright(at_a) and dark(at_b), first
    assert first["hud-pose"].startswith("x 1.00"), first

    move_to(robot, url, b)
    second = load_page(page, tmp_path / "profile")
    at_a, at_b = (colour(c) for c in second["probe"].split(";"))
    assert dark(at_a) and bright(at_b), second
    assert second["checksum"] != first["checksum"]
    assert second["robot-px"] != first["robot-px"]
    assert second["hud-pose"].startswith("x \u22121.50"), second
