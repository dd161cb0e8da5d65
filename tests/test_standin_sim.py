"""The simulator and spawner stand-ins: their command lines (pure), and real processes talking
ROS (a sim with an inline world, spawners with inline URDFs, and a probe child that drives the
robot and reports what it saw as JSON)."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import wait_until

from mlaunch.standins.sim import SimUsageError, free_name, parse_sim_args, parse_spawn_request
from mlaunch.standins.spawn import SpawnError, parse_spawn_args, spawn_request

WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="test_world">
    <model name="ground_plane"><static>true</static><link name="l"><collision name="c">
      <geometry><plane><normal>0 0 1</normal></plane></geometry></collision></link></model>
    <model name="wall">
      <static>true</static>
      <pose>3 0 0.5 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><box><size>0.2 4 1</size></box>
      </geometry></collision></link>
    </model>
  </world>
</sdf>
"""

# A small diff-drive robot: base 0.4 x 0.3 (footprint radius 0.25), lidar 0.1 ahead of the base
# origin, so the wall face at x = 2.9 is 2.8 away from the lidar at the start.
URDF = """<?xml version="1.0"?>
<robot name="testbot">
  <link name="base_link"><collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision>
  </link>
  <link name="left_wheel"><collision><origin rpy="1.5707963 0 0"/>
    <geometry><cylinder radius="0.05" length="0.04"/></geometry></collision></link>
  <link name="right_wheel"><collision><origin rpy="1.5707963 0 0"/>
    <geometry><cylinder radius="0.05" length="0.04"/></geometry></collision></link>
  <link name="laser"><collision><geometry><cylinder radius="0.03" length="0.04"/></geometry>
  </collision></link>
  <link name="imu_link"/>
  <joint name="left_wheel_joint" type="continuous"><parent link="base_link"/>
    <child link="left_wheel"/><origin xyz="0 0.175 0"/><axis xyz="0 1 0"/></joint>
  <joint name="right_wheel_joint" type="continuous"><parent link="base_link"/>
    <child link="right_wheel"/><origin xyz="0 -0.175 0"/><axis xyz="0 1 0"/></joint>
  <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/>
    <origin xyz="0.1 0 0.07"/></joint>
  <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  <gazebo>
    <plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">
      <ros></ros>
      <left_joint>left_wheel_joint</left_joint>
      <right_joint>right_wheel_joint</right_joint>
      <wheel_separation>0.35</wheel_separation>
      <wheel_diameter>0.1</wheel_diameter>
      <max_wheel_acceleration>2.0</max_wheel_acceleration>
      <publish_odom>true</publish_odom>
      <odometry_frame>odom</odometry_frame>
      <robot_base_frame>base_link</robot_base_frame>
    </plugin>
  </gazebo>
  <gazebo reference="laser">
    <sensor name="lidar" type="ray">
      <update_rate>10</update_rate>
      <ray>
        <scan><horizontal><samples>72</samples><resolution>1</resolution>
          <min_angle>0</min_angle><max_angle>6.2</max_angle></horizontal></scan>
        <range><min>0.1</min><max>5.0</max></range>
        <noise><type>gaussian</type><mean>0</mean><stddev>0.005</stddev></noise>
      </ray>
      <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
        <ros><remapping>~/out:=scan</remapping></ros>
        <output_type>sensor_msgs/LaserScan</output_type>
        <frame_name>laser</frame_name>
      </plugin>
    </sensor>
  </gazebo>
  <gazebo reference="imu_link">
    <sensor name="imu_sensor" type="imu">
      <update_rate>50</update_rate>
      <plugin filename="libgazebo_ros_imu_sensor.so" name="imu_plugin">
        <ros><remapping>~/out:=imu</remapping></ros>
      </plugin>
    </sensor>
  </gazebo>
</robot>
"""

WALL_FACE = 2.9
RADIUS = math.hypot(0.2, 0.15)

# The ROS side of the checks, run as a child so this test process never imports rclpy.
# argv[1] is a JSON plan; it prints one JSON object (or {"error": ...}) and exits.
PROBE = r"""
import json, math, sys, time
import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState, LaserScan

plan = json.loads(sys.argv[1])
rclpy.init()
node = rclpy.create_node("probe")
latest = {}

def keep(name):
    def store(msg):
        latest[name] = (time.monotonic(), msg)
    return store

for name, kind in (("/clock", Clock), ("/odom", Odometry), ("/scan", LaserScan),
                   ("/imu", Imu), ("/joint_states", JointState)):
    node.create_subscription(kind, name, keep(name), 10)
cmd = node.create_publisher(Twist, "/cmd_vel", 10)

def spin_until(pred, timeout):
    deadline = time.monotonic() + timeout
    while not pred():
        if time.monotonic() > deadline:
            print(json.dumps({"error": "timeout", "have": sorted(latest)}))
            sys.exit(3)
        rclpy.spin_once(node, timeout_sec=0.02)

def stamp(msg):
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9

def snapshot():
    clock = latest["/clock"][1].clock
    odom = latest["/odom"][1]
    scan = latest["/scan"][1]
    imu = latest["/imu"][1]
    js = latest["/joint_states"][1]
    return {
        "wall": time.monotonic(),
        "clock": clock.sec + clock.nanosec * 1e-9,
        "odom_stamp": stamp(odom),
        "x": odom.pose.pose.position.x,
        "y": odom.pose.pose.position.y,
        "vx": odom.twist.twist.linear.x,
        "frame": [odom.header.frame_id, odom.child_frame_id],
        "scan_front": scan.ranges[0],
        "scan_back": scan.ranges[len(scan.ranges) // 2],
        "scan_n": len(scan.ranges),
        "scan_frame": scan.header.frame_id,
        "scan_stamp": stamp(scan),
        "imu_az": imu.linear_acceleration.z,
        "joints": dict(zip(js.name, js.position)),
    }

def fresh_scan_after(t):
    spin_until(lambda: stamp(latest["/scan"][1]) > t, 10)

def drive(speed, until, timeout):
    twist = Twist()
    twist.linear.x = speed
    deadline = time.monotonic() + timeout
    last = 0.0
    while not until():
        if time.monotonic() > deadline:
            break
        if time.monotonic() - last > 0.05:
            cmd.publish(twist)
            last = time.monotonic()
        rclpy.spin_once(node, timeout_sec=0.02)
    cmd.publish(Twist())

out = {}
spin_until(lambda: len(latest) == 5, 20)
out["before"] = snapshot()
start_x = out["before"]["x"]
drive(plan["speed"], lambda: latest["/odom"][1].pose.pose.position.x > start_x + plan["distance"], 15)
spin_until(lambda: abs(latest["/odom"][1].twist.twist.linear.x) < 1e-9, 10)
fresh_scan_after(stamp(latest["/odom"][1]))
out["after"] = snapshot()
if plan.get("crash"):
    history = []
    def stalled():
        odom = latest["/odom"][1]
        history.append((stamp(odom), odom.pose.pose.position.x))
        old = [x for t, x in history if t < history[-1][0] - 0.5]
        return bool(old) and abs(old[-1] - history[-1][1]) < 1e-9
    drive(plan["crash"], stalled, 20)
    out["crashed"] = snapshot()
print(json.dumps(out))
"""


# ---------------------------------------------------------------- pure: command lines


def test_classic_gazebo_command_line() -> None:
    options = parse_sim_args(
        [
            "--verbose",
            "/w/jt.world",
            "-s",
            "libgazebo_ros_init.so",
            "-s",
            "libgazebo_ros_factory.so",
        ]
    )
    assert options.flavor == "gazebo" and options.world == "/w/jt.world"
    assert options.ignored == []  # the stand-in provides /clock and spawning itself
    options = parse_sim_args(["-u", "-s", "libgazebo_ros_state.so", "w.world", "extra"])
    assert options.ignored == ["-u", "-s libgazebo_ros_state.so", "argument 'extra'"]
    assert parse_sim_args(["gzserver", "--seed", "5", "a.world"]).seed == 5
    assert parse_sim_args([]).world is None


def test_gz_sim_command_line() -> None:
    options = parse_sim_args(["sim", "-r", "-v", "4", "empty.sdf"])
    assert options.flavor == "gz" and options.world == "empty.sdf" and options.ignored == []
    options = parse_sim_args(["gz", "sim", "-s", "-v", "shapes.sdf", "--bogus"])
    assert options.world == "shapes.sdf"
    assert "unknown option --bogus" in options.ignored
    assert any("missing -r" in note for note in options.ignored)
    assert parse_sim_args(["gazebo", "-r", "w.sdf"]).flavor == "gz"  # `ign gazebo` arguments
    with pytest.raises(SimUsageError):
        parse_sim_args(["--seed", "abc"])


def test_spawn_entity_command_line() -> None:
    options = parse_spawn_args(
        [
            *("spawn_entity.py", "-entity", "jtbot", "-topic", "robot_description"),
            *("-x", "-1.5", "-Y", "0.5", "-timeout", "12"),
        ]
    )
    assert (options.flavor, options.name, options.source, options.value) == (
        "gazebo_ros",
        "jtbot",
        "topic",
        "robot_description",
    )
    assert options.pose == (-1.5, 0.0, 0.0, 0.0, 0.0, 0.5) and options.timeout == 12
    request = json.loads(spawn_request(options, "<robot/>", "abc", "/"))
    assert request["x"] == -1.5 and request["yaw"] == 0.5 and request["id"] == "abc"
    assert "robot_namespace" not in request
    namespaced = json.loads(spawn_request(options, "<robot/>", "abc", "/r1"))
    assert namespaced["robot_namespace"] == "/r1"


def test_create_command_line() -> None:
    options = parse_spawn_args(
        ["create", "-name", "bot", "--file=/tmp/x.urdf", "-allow_renaming=true", "-world", "w"]
    )
    assert (options.flavor, options.name, options.source, options.value) == (
        "ros_gz_sim",
        "bot",
        "file",
        "/tmp/x.urdf",
    )
    assert options.allow_renaming and options.ignored == ["-world w"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["spawn_entity.py", "-entity", "a", "-file", "f", "-bogus", "1"],
            "unknown option '-bogus'",
        ),
        (["spawn_entity.py", "-file", "f"], "-entity"),
        (["spawn_entity.py", "-entity", "a"], "one of the arguments"),
        (["spawn_entity.py", "-entity", "a", "-file", "f", "-timeout", "0"], "-timeout is 0.0"),
        (["create", "-name", "a", "-string", "x", "-allow_renaming=maybe"], "'maybe'"),
        (["spawn_entity.py", "-entity", "a", "-database", "box"], "model database"),
        (["rosrun", "-entity", "a"], "first argument names the program"),
    ],
)
def test_bad_spawn_command_lines(args: list[str], message: str) -> None:
    with pytest.raises(SpawnError) as info:
        parse_spawn_args(args)
    assert message in str(info.value)


def test_spawn_request_validation() -> None:
    request = parse_spawn_request(json.dumps({"name": "a", "urdf": "<robot/>", "x": 1}))
    assert request.pose == (1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for bad, why in (
        ("not json", "not JSON"),
        (json.dumps({"urdf": "x"}), "'name'"),
        (json.dumps({"name": "a", "urdf": "x", "y": "1"}), "'y' must be a finite number"),
        (json.dumps({"name": "a"}), "'urdf'"),
    ):
        with pytest.raises(ValueError, match=why):
            parse_spawn_request(bad)
    assert free_name("a", {"a": 1, "a_1": 2}) == "a_2"


# ---------------------------------------------------------------- processes


class Sim:
    """A running simulator stand-in with its output in files."""

    def __init__(self, tmp: Path, env: dict[str, str], *args: str):
        self.out = tmp / "sim.out"
        self.err = tmp / "sim.err"
        with self.out.open("wb") as out, self.err.open("wb") as err:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "mlaunch.standins.sim", *args],
                stdout=out,
                stderr=err,
                env=env,
                cwd=tmp,
            )

    def stdout(self) -> str:
        return self.out.read_text()

    def stderr(self) -> str:
        return self.err.read_text()

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


@pytest.fixture
def world_file(tmp_path: Path) -> Path:
    path = tmp_path / "test.world"
    path.write_text(WORLD)
    return path


@pytest.fixture
def sim_factory(tmp_path: Path, ros_env: dict[str, str]) -> Iterator[Callable[..., Sim]]:
    started: list[Sim] = []

    def start(*args: str) -> Sim:
        sim = Sim(tmp_path, ros_env, *args)
        started.append(sim)
        return sim

    try:
        yield start
    finally:
        for sim in started:
            sim.stop()


def run(
    module: str, args: list[str], env: dict[str, str], timeout: float = 30, cwd: Path | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
    )


def spawn(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return run("mlaunch.standins.spawn", args, env)


@requires_rclpy
def test_spawn_drive_scan_collide_and_stop(
    tmp_path: Path, ros_env: dict[str, str], world_file: Path, sim_factory: Callable[..., Sim]
) -> None:
    urdf = tmp_path / "testbot.urdf"
    urdf.write_text(URDF)
    sim = sim_factory(
        "--verbose",
        str(world_file),
        "-s",
        "libgazebo_ros_init.so",
        "-s",
        "libgazebo_ros_state.so",
        "--ros-args",
        "-p",
        "use_sim_time:=true",
        "-p",
        "real_time_factor:=2.0",
    )
    done = spawn(["spawn_entity.py", "-entity", "testbot", "-file", str(urdf)], ros_env)
    assert done.returncode == 0, done.stderr
    assert "spawned entity 'testbot'" in done.stdout

    plan = {"speed": 0.5, "distance": 0.5, "crash": 1.0}
    probe = subprocess.run(
        [sys.executable, "-c", PROBE, json.dumps(plan)],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert probe.returncode == 0, probe.stdout + probe.stderr
    seen = json.loads(probe.stdout.strip().splitlines()[-1])
    before, after, crashed = seen["before"], seen["after"], seen["crashed"]

    # /clock advances, at about twice the wall-clock rate (real_time_factor 2).
    assert after["clock"] > before["clock"]
    rate = (crashed["clock"] - before["clock"]) / (crashed["wall"] - before["wall"])
    assert 1.25 < rate < 2.6, rate  # generous below: a loaded machine may slow the sim
    # Odometry: frames from the plugin, the robot moved forward, stamps are sim time.
    assert before["frame"] == ["odom", "base_link"]
    moved = after["x"] - before["x"]
    assert moved > 0.5 and abs(after["y"]) < 1e-6
    assert after["odom_stamp"] <= after["clock"] + 0.05
    # The lidar (0.1 ahead of the base) sees the wall face closer by what the robot drove.
    assert before["scan_n"] == 72 and before["scan_frame"] == "laser"
    assert before["scan_front"] == pytest.approx(WALL_FACE - 0.1 - before["x"], abs=0.03)
    assert after["scan_front"] == pytest.approx(WALL_FACE - 0.1 - after["x"], abs=0.03)
    assert math.isinf(before["scan_back"])  # nothing behind the robot within range_max
    # Wheels turned by distance / radius; the IMU feels gravity.
    assert after["joints"]["left_wheel_joint"] == pytest.approx(after["x"] / 0.05, rel=0.02)
    assert before["imu_az"] == pytest.approx(9.8, abs=0.1)
    # Driving on into the wall stops the robot where its footprint touches it.
    assert WALL_FACE - RADIUS - 0.03 < crashed["x"] <= WALL_FACE - RADIUS + 1e-9
    assert crashed["vx"] == 0.0

    # A second model with the same name is refused by the simulator.
    dup = spawn(["spawn_entity.py", "-entity", "testbot", "-string", URDF, "-y", "2"], ros_env)
    assert dup.returncode == 1
    assert "already exists" in dup.stderr and dup.stderr.count("\n") == 1
    # A URDF the simulator cannot drive (diff drive names a missing joint) is refused with why.
    broken = URDF.replace("<left_joint>left_wheel_joint", "<left_joint>front_wheel_joint")
    bad = spawn(["spawn_entity.py", "-entity", "other", "-string", broken], ros_env)
    assert bad.returncode == 1 and "'front_wheel_joint' is not in the URDF" in bad.stderr
    # Malformed XML is refused by the spawner itself.
    bad = spawn(["create", "-name", "third", "-string", "<robot name='x'><link>"], ros_env)
    assert bad.returncode == 1 and "bad URDF" in bad.stderr and "not well-formed" in bad.stderr

    out = sim.stdout()
    assert "world 'test_world'" in out and "1 shapes" in out
    assert "spawned model 'testbot'" in out and "lidar /scan @10 Hz" in out
    assert "ignored by the stand-in: -s libgazebo_ros_state.so\n" in sim.stderr()

    sim.proc.send_signal(signal.SIGINT)
    assert sim.proc.wait(timeout=5) == 0  # promptly: the deadline bounds it
    assert "Traceback" not in sim.stderr()


@requires_rclpy
def test_spawn_from_latched_topic_in_namespace(
    tmp_path: Path, ros_env: dict[str, str], sim_factory: Callable[..., Sim]
) -> None:
    sim = sim_factory()  # no world: an empty one
    publisher = subprocess.Popen(
        [sys.executable, "-c", LATCHED_PUBLISHER, "/r1/robot_description"],
        stdin=subprocess.PIPE,
        env=ros_env,
        text=True,
    )
    try:
        assert publisher.stdin is not None
        publisher.stdin.write(URDF)
        publisher.stdin.close()
        done = spawn(
            [
                *("spawn_entity.py", "-entity", "r1", "-topic", "robot_description"),
                *("--ros-args", "-r", "__ns:=/r1"),
            ],
            ros_env,
        )
    finally:
        publisher.kill()
        publisher.wait()
    assert done.returncode == 0, done.stderr
    # spawn_entity's -robot_namespace defaults to its own namespace and moves the plugins there.
    assert wait_until(lambda: "spawned model 'r1'" in sim.stdout(), 5)
    assert "/r1/cmd_vel -> /r1/odom" in sim.stdout() and "lidar /r1/scan" in sim.stdout()
    assert "empty world" in sim.stdout()
    sim.proc.send_signal(signal.SIGTERM)
    assert sim.proc.wait(timeout=5) == 0


LATCHED_PUBLISHER = r"""
import sys, rclpy
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_msgs.msg import String
text = sys.stdin.read()
rclpy.init()
node = rclpy.create_node("rsp")
pub = node.create_publisher(String, sys.argv[1], QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
pub.publish(String(data=text))
try:
    rclpy.spin(node)
except BaseException:
    pass
"""


@requires_rclpy
def test_spawner_gives_up_without_a_simulator(tmp_path: Path, ros_env: dict[str, str]) -> None:
    urdf = tmp_path / "r.urdf"
    urdf.write_text(URDF)
    done = spawn(["spawn_entity.py", "-entity", "r", "-file", str(urdf), "-timeout", "1"], ros_env)
    assert done.returncode == 1
    assert "timed out after 1 s" in done.stderr and "no simulator is running" in done.stderr
    done = spawn(["spawn_entity.py", "-entity", "r", "-file", str(tmp_path / "none.urdf")], ros_env)
    assert done.returncode == 1 and "none.urdf' does not exist" in done.stderr


@requires_rclpy
def test_sim_refuses_missing_or_malformed_world(tmp_path: Path, ros_env: dict[str, str]) -> None:
    done = run("mlaunch.standins.sim", ["missing.world"], ros_env, cwd=tmp_path)
    assert done.returncode == 1
    assert "missing.world" in done.stderr and "does not exist" in done.stderr
    assert done.stderr.count("\n") == 1
    bad = tmp_path / "bad.world"
    bad.write_text('<sdf version="1.6">\n  <world name="w">\n    <model>\n  </world>\n</sdf>\n')
    done = run("mlaunch.standins.sim", ["--verbose", str(bad)], ros_env)
    assert done.returncode == 1 and f"{bad}:4" in done.stderr
    done = run("mlaunch.standins.sim", ["empty.world"], ros_env | {"MLAUNCH_SIM_RTF": "0"})
    assert done.returncode == 1 and "real_time_factor is 0.0" in done.stderr
