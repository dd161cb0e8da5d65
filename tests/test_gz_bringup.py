"""Modern Gazebo (gz sim) bringups on the stand-ins: ros_gz_sim's launch files from the
stand-ins' share, SDF robot models spawned with ``ros_gz_sim create``, ros_gz_bridge's
parameter_bridge with a YAML config (a renamed topic relayed, cmd_vel as TwistStamped), and a
package with no stand-in named with what to install."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import REPO, Running, clean_env, mlaunch, run_mlaunch

from mlaunch import standins
from mlaunch.ros.packages import PackageIndex, PackageNotFoundError
from mlaunch.standins.gz_bridge import BridgeError, gz_name, parse_config, parse_spec
from mlaunch.standins.sdf_model import SdfError, is_sdf, sdf_to_urdf
from mlaunch.standins.urdf import parse_urdf

BRINGUP = REPO / "tests/launches/gz_bringup/gzbot_gazebo"
LAUNCH = BRINGUP / "launch/gzbot_world.launch.py"
MODEL = BRINGUP / "models/gzbot/model.sdf"


# ---------------------------------------------------------------- SDF models as URDF


def test_an_sdf_model_becomes_the_urdf_robot_it_describes() -> None:
    text = MODEL.read_text()
    assert is_sdf(text) and not is_sdf("<robot name='r'><link name='a'/></robot>")
    # xacro puts a long comment banner before the root element.
    assert is_sdf(f"<?xml version='1.0'?>\n<!-- {'=' * 500} -->\n<sdf version='1.8'/>")
    assert not is_sdf(f"<?xml version='1.0'?>\n<!-- {'=' * 500} <sdf> -->\n<robot/>")
    translation = sdf_to_urdf(text, str(MODEL))
    robot = parse_urdf(translation.urdf)
    assert robot.name == "gzbot" and robot.root == "base_footprint"
    joints = robot.joints
    # The wheel's pose in the model frame, seen from base_link (0.05 up): 0.15 to the side.
    left = joints["wheel_left_joint"]
    assert left.type == "continuous"  # SDF's revolute without limits turns freely
    assert left.origin_xyz == pytest.approx((0.0, 0.15, 0.0), abs=1e-9)
    assert left.origin_rpy == pytest.approx((-1.5707963, 0.0, 0.0), abs=1e-7)
    assert left.axis == pytest.approx((0.0, 0.0, 1.0))
    assert joints["lidar_joint"].origin_xyz == pytest.approx((0.1, 0.0, 0.07), abs=1e-9)
    # The ball caster has no URDF type: held fixed, and said so.
    assert joints["caster_joint"].type == "fixed"
    assert translation.notes == ["joint 'caster_joint' of type 'ball' is held fixed"]
    # The model's plugins and the link's sensor are <gazebo> blocks, as the simulator reads them.
    plugin = next(b for b in robot.gazebo if b.get("reference") is None).find("plugin")
    assert plugin is not None and plugin.get("filename") == "gz-sim-diff-drive-system"
    sensor_block = next(b for b in robot.gazebo if b.get("reference") == "lidar_link")
    assert sensor_block.find("sensor/topic").text == "scan"  # type: ignore[union-attr]


def test_links_no_joint_holds_ride_on_the_root_as_posed() -> None:
    sdf = """<sdf version="1.8"><model name="m">
      <link name="a"/><link name="b"><pose>1 2 0 0 0 1.5707963</pose></link>
    </model></sdf>"""
    translation = sdf_to_urdf(sdf)
    joint = parse_urdf(translation.urdf).joints["b_fixed"]
    assert (joint.parent, joint.child, joint.type) == ("a", "b", "fixed")
    assert joint.origin_xyz == pytest.approx((1.0, 2.0, 0.0))
    assert joint.origin_rpy[2] == pytest.approx(math.pi / 2, abs=1e-7)
    assert translation.notes == ["link 'b' is joined to no other link: fixed to 'a'"]


@pytest.mark.parametrize(
    ("sdf", "message"),
    [
        ("<sdf><world name='w'/></sdf>", "m.sdf: the SDF holds a world, not a model"),
        ("<sdf><model name='m'/></sdf>", "m.sdf: model 'm': has no <link>"),
        ("<sdf><model name='m'><link name='a'", "m.sdf: not well-formed XML"),
        (
            "<sdf><model name='m'><link name='a'><pose>1 2</pose></link></model></sdf>",
            "<pose> of link 'a' is '1 2'; expected six numbers: x y z roll pitch yaw",
        ),
        (
            "<sdf><model name='m'><link name='a'/><joint name='j' type='fixed'>"
            "<parent>a</parent><child>wheel</child></joint></model></sdf>",
            "joint 'j' has <child> 'wheel', which is no link of the model (links: a)",
        ),
    ],
)
def test_an_unusable_sdf_model_is_refused_with_why(sdf: str, message: str) -> None:
    with pytest.raises(SdfError) as caught:
        sdf_to_urdf(sdf, "m.sdf")
    assert message in str(caught.value)


# ---------------------------------------------------------------- the bridge's input


def test_bridge_specs_read_as_parameter_bridge_reads_them() -> None:
    both = parse_spec("/chatter@std_msgs/msg/String@gz.msgs.StringMsg")
    assert (both.ros_topic, both.ros_type, both.gz_type, both.direction) == (
        "/chatter",
        "std_msgs/msg/String",
        "gz.msgs.StringMsg",
        "BIDIRECTIONAL",
    )
    assert parse_spec("/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock").direction == "GZ_TO_ROS"
    assert parse_spec("/cmd@geometry_msgs/Twist]gz.msgs.Twist").ros_type == (
        "geometry_msgs/msg/Twist"
    )
    for bad in ("chatter", "/c@std_msgs/msg/String", "/c@String@gz.msgs.StringMsg"):
        with pytest.raises(BridgeError):
            parse_spec(bad)
    assert gz_name("model/gzbot/odometry") == "/model/gzbot/odometry"


def test_bridge_config_files_are_checked_entry_by_entry() -> None:
    bridges = parse_config((BRINGUP / "params/bridge.yaml").read_text(), "bridge.yaml")
    assert [(b.ros_topic, b.gz_topic, b.direction) for b in bridges] == [
        ("odom", "model/gzbot/odometry", "GZ_TO_ROS"),
        ("cmd_vel", "cmd_vel", "ROS_TO_GZ"),
        ("scan", "scan", "GZ_TO_ROS"),
        ("clock", "clock", "GZ_TO_ROS"),
    ]
    cases = {
        "- topic_name: a\n  ros_type_name: std_msgs/msg/String\n  gz_type_name: g\n"
        "  direction: BOTH\n": "bridge 1: direction 'BOTH' is not one of BIDIRECTIONAL",
        "- topic_name: a\n  ros_type_name: std_msgs/msg/String\n": "bridge 1: needs gz_type_name",
        "- topic: a\n": "bridge 1: unknown key 'topic' (valid: direction, gz_topic_name",
        "a: b\n": "expected a list of bridges, got a dict",
        "- [": "is not valid YAML",
    }
    for text, message in cases.items():
        with pytest.raises(BridgeError) as caught:
            parse_config(text, "c.yaml")
        assert message in str(caught.value)


# ---------------------------------------------------------------- shares and programs


def test_gz_command_lines_pick_the_simulator_or_the_viewer() -> None:
    if not standins.rclpy_available():
        pytest.skip("the stand-ins need rclpy")
    server = standins.standin_for(["gz", "sim", "-r", "-s", "w.sdf"])
    assert server is not None and server[2:] == ["mlaunch.standins.sim", "sim", "-r", "-s", "w.sdf"]
    gui = standins.standin_for(["gz", "sim", "-g", "-v2"])
    assert gui is not None and gui[2:] == ["mlaunch.standins.viewer"]
    # Classic gazebo's -g names a GUI plugin: still the simulator.
    classic = standins.standin_for(["gazebo", "-g", "libgui.so", "w.world"])
    assert classic is not None and classic[2] == "mlaunch.standins.sim"


def test_the_standins_share_answers_last_and_only_with_standins(tmp_path: Path) -> None:
    index = PackageIndex({}, standins=True)
    found = index.get("ros_gz_sim")
    assert found.standin and (Path(found.share_directory) / "launch/gz_sim.launch.py").is_file()
    with pytest.raises(PackageNotFoundError) as caught:
        index.executable("ros_gz_sim", "gz_server")
    assert "mlaunch's stand-ins serve its launch files, but not its executable 'gz_server'" in str(
        caught.value
    )
    with pytest.raises(PackageNotFoundError) as caught:
        PackageIndex({}, standins=False).get("ros_gz_sim")
    assert str(caught.value).endswith(
        "mlaunch's stand-ins serve its launch files: run without --no-standins"
    )
    # A checked-out package of the same name wins over the stand-in's share.
    (tmp_path / "ros_gz_sim").mkdir()
    (tmp_path / "ros_gz_sim/package.xml").write_text(
        "<package format='3'><name>ros_gz_sim</name></package>"
    )
    own = PackageIndex({}, explicit_paths=(str(tmp_path),), standins=True).get("ros_gz_sim")
    assert not own.standin and own.share_directory == str(tmp_path / "ros_gz_sim")


def test_a_package_with_no_standin_names_the_include_and_what_to_install(tmp_path: Path) -> None:
    launch = tmp_path / "nav.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import IncludeLaunchDescription\n"
        "from launch.substitutions import PathJoinSubstitution\n"
        "from launch_ros.substitutions import FindPackageShare\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([IncludeLaunchDescription(PathJoinSubstitution(\n"
        "        [FindPackageShare('nav2_bringup'), 'launch', 'bringup_launch.py']))])\n"
    )
    done = run_mlaunch(str(launch), "--print", env=clean_env(AMENT_PREFIX_PATH=""))
    assert done.returncode != 0
    line = done.stderr.strip()
    assert line.count("\n") == 0, done.stderr
    assert f"{launch}:6: IncludeLaunchDescription(" in line
    assert "package 'nav2_bringup' not found" in line
    assert line.endswith(
        "mlaunch has no stand-in for it: install it (sudo apt install ros-jazzy-nav2-bringup,"
        " then source /opt/ros/jazzy/setup.bash)"
    )


def test_the_bringup_plan_runs_gz_create_and_the_bridge_on_standins() -> None:
    if not standins.rclpy_available():
        pytest.skip("the stand-ins need rclpy")
    done = run_mlaunch(str(LAUNCH), "--print", "--format", "json", env=clean_env())
    assert done.returncode == 0, done.stderr
    steps = json.loads(done.stdout)["steps"]
    processes = {s["label"]: s for s in steps if s["kind"] == "process"}
    assert list(processes) == ["gazebo-1", "gazebo-2", "create-3", "parameter_bridge-4"]
    server = processes["gazebo-1"]["argv"]
    assert server[1:4] == ["-m", "mlaunch.standins.sim", "sim"]
    assert server[-1] == str(BRINGUP / "worlds/walls.world")
    # The package's exported model folder reaches the simulator (model://gz_walls).
    assert processes["gazebo-1"]["env"]["set"]["GZ_SIM_RESOURCE_PATH"] == str(BRINGUP / "models")
    assert processes["gazebo-2"]["argv"][1:] == ["-m", "mlaunch.standins.viewer"]
    assert processes["create-3"]["argv"][1:4] == ["-m", "mlaunch.standins.spawn", "create"]
    assert processes["parameter_bridge-4"]["argv"][1:4] == [
        "-m",
        "mlaunch.standins.gz_bridge",
        "parameter_bridge",
    ]


PROBE = r"""
import json, math, sys, time
import rclpy
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
rclpy.init()
node = rclpy.create_node("gz_probe")
seen = {}
node.create_subscription(Odometry, "/odom", lambda m: seen.__setitem__("odom", m), 10)
node.create_subscription(LaserScan, "/scan", lambda m: seen.__setitem__("scan", m), 10)
cmd = node.create_publisher(TwistStamped, "/cmd_vel", 10)
def spin_until(what, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end and not what():
        rclpy.spin_once(node, timeout_sec=0.1)
    return what()
assert spin_until(lambda: "odom" in seen and "scan" in seen, 60), sorted(seen)
before = seen["odom"].pose.pose.position.x
front = seen["scan"].ranges[len(seen["scan"].ranges) // 2]
msg = TwistStamped()
msg.twist.linear.x = 0.5
def moved():
    cmd.publish(msg)
    return seen["odom"].pose.pose.position.x > before + 0.3
ok = spin_until(moved, 60)
print(json.dumps({"before": before, "after": seen["odom"].pose.pose.position.x, "front": front,
                  "frame": seen["odom"].header.frame_id, "moved": ok}))
"""


@requires_rclpy
@pytest.mark.slow
def test_the_bringup_drives_with_twiststamped_and_relays_odometry(
    ros_env: dict[str, str],
) -> None:
    run = Running(mlaunch(str(LAUNCH)), env=clean_env(**ros_env))
    try:
        run.wait_for(r"create: spawned entity 'gzbot'", timeout=90)
        run.wait_for(r"relayed /model/gzbot/odometry -> /odom", timeout=30)
        run.wait_for(r"/cmd_vel takes geometry_msgs/msg/TwistStamped \(bridged\)", timeout=30)
        probe = subprocess.run(
            [sys.executable, "-c", PROBE],
            env=ros_env,
            capture_output=True,
            text=True,
            timeout=150,
        )
        assert probe.returncode == 0, probe.stdout + probe.stderr + run.text
        seen = json.loads(probe.stdout.strip().splitlines()[-1])
        assert seen["moved"], (seen, run.text)
        assert seen["frame"] == "odom"
        # The wall's face is 2.9 ahead of the start; the lidar sits 0.1 ahead of the base.
        assert seen["front"] == pytest.approx(2.8 - seen["before"], abs=0.05)
        assert "Fuel" not in run.text  # the ground plane and the sun need no download
        assert "Traceback" not in run.text
    finally:
        run.kill()
