"""TF from the stand-ins: robot_state_publisher and static_transform_publisher on /tf and /tf_static.

Each test runs the stand-in as a process with the command line a launch gives it, and a probe
child that listens on /tf_static (latched) and /tf, optionally publishes joint states, and prints
the transforms it saw as JSON lines. Needs tf2_msgs (scripts/setup builds it).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from procutil import wait_for
from test_interfaces import requires_tf2_msgs
from test_standin_nodes import URDF, Proc, params_file, spawn, standin, started

pytestmark = [requires_tf2_msgs, pytest.mark.timeout(60)]
__all__ = ["spawn"]  # the fixture, used by name

TF_PROBE = textwrap.dedent(
    r"""
    import json, sys, time
    import rclpy
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from tf2_msgs.msg import TFMessage

    spec = json.loads(sys.argv[1])
    rclpy.init()
    node = Node("tf_probe")
    deadline = time.monotonic() + spec.get("timeout", 20)
    seen = {"/tf": {}, "/tf_static": {}}

    def keep(topic):
        def on(msg):
            for t in msg.transforms:
                tr, r = t.transform.translation, t.transform.rotation
                seen[topic][t.child_frame_id] = {
                    "parent": t.header.frame_id, "xyz": [tr.x, tr.y, tr.z],
                    "q": [r.x, r.y, r.z, r.w],
                    "stamp": [t.header.stamp.sec, t.header.stamp.nanosec]}
        return on

    # Depth 100 as tf2's static listener: each static broadcaster latches its own message, and
    # with depth 1 one that arrives while the other waits to be taken replaces it.
    latched = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_subscription(TFMessage, "/tf_static", keep("/tf_static"), latched)
    node.create_subscription(TFMessage, "/tf", keep("/tf"), 100)
    if spec.get("joints"):
        from sensor_msgs.msg import JointState
        pub = node.create_publisher(JointState, "joint_states", 10)

        def send():
            msg = JointState(name=list(spec["joints"]), position=list(spec["joints"].values()))
            msg.header.stamp = node.get_clock().now().to_msg()
            pub.publish(msg)
        node.create_timer(0.05, send)
    want = {topic: set(children) for topic, children in spec["want"].items()}
    while not all(want[t] <= set(seen[t]) for t in want):
        if time.monotonic() > deadline:
            print(json.dumps({"timeout": True, "seen": seen}), flush=True)
            sys.exit(3)
        rclpy.spin_once(node, timeout_sec=0.05)
    print(json.dumps(seen), flush=True)
    node.destroy_node()
    rclpy.shutdown()
    """
)


def tf_probe(spawn: Callable[..., Proc], spec: dict[str, Any]) -> dict[str, Any]:
    proc = spawn([sys.executable, "-c", TF_PROBE, json.dumps(spec)], "tf_probe")
    try:
        proc.popen.wait(timeout=spec.get("timeout", 20) + 10)
    except subprocess.TimeoutExpired:
        proc.stop()
    assert proc.popen.returncode == 0, f"{proc.stdout()[-3000:]} {proc.stderr()[-2000:]}"
    result: dict[str, Any] = json.loads(proc.stdout().splitlines()[-1])
    return result


def close(a: list[float], b: list[float]) -> bool:
    return all(math.isclose(x, y, abs_tol=1e-9) for x, y in zip(a, b, strict=True))


def test_rsp_publishes_fixed_joints_static_and_moving_joints_from_joint_states(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    params = params_file(tmp_path, {"robot_description": URDF, "frame_prefix": "r1/"})
    rsp = spawn(standin("rsp", "--ros-args", "--params-file", params), "rsp")
    wait_for(started(rsp, "Robot initialized"), 15, "rsp to start")
    seen = tf_probe(
        spawn,
        {
            "want": {"/tf_static": ["r1/laser"], "/tf": ["r1/arm", "r1/left_wheel"]},
            "joints": {"arm_joint": math.pi / 2, "left_wheel_joint": 0.0},
        },
    )
    laser = seen["/tf_static"]["r1/laser"]
    assert laser["parent"] == "r1/base_link"
    assert close(laser["xyz"], [0.1, 0.0, 0.2]) and close(laser["q"], [0.0, 0.0, 0.0, 1.0])
    arm = seen["/tf"]["r1/arm"]
    # a quarter turn about z: (0, 0, sin 45°, cos 45°)
    half = math.sqrt(0.5)
    assert arm["parent"] == "r1/base_link" and close(arm["q"], [0.0, 0.0, half, half])
    # only the joints named in joint_states are published, and never a fixed one on /tf
    assert set(seen["/tf"]) == {"r1/arm", "r1/left_wheel"}
    assert set(seen["/tf_static"]) == {"r1/laser"}


def test_rsp_refuses_a_publish_frequency_out_of_range(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    params = params_file(tmp_path, {"robot_description": URDF, "publish_frequency": 0.0})
    rsp = spawn(standin("rsp", "--ros-args", "--params-file", params), "rsp")
    assert rsp.popen.wait(timeout=20) == 1
    errors = [line for line in rsp.stderr().splitlines() if "ERROR" in line]
    assert len(errors) == 1
    assert "'publish_frequency' is 0.0; it must be above 0 and at most 1000" in errors[0]


# ---------------------------------------------------------------- static_transform_publisher


def test_stp_flag_form_with_rpy_and_the_real_node_name(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    argv = ["--x", "1", "--y", "-2", "--yaw", str(math.pi / 2), "--frame-id", "map"]
    stp = spawn(standin("stp", *argv, "--child-frame-id", "odom"), "stp")
    wait_for(started(stp, "Spinning until stopped"), 15, "stp to start")
    seen = tf_probe(spawn, {"want": {"/tf_static": ["odom"]}})
    odom = seen["/tf_static"]["odom"]
    half = math.sqrt(0.5)
    assert odom["parent"] == "map"
    assert close(odom["xyz"], [1.0, -2.0, 0.0]) and close(odom["q"], [0.0, 0.0, half, half])
    assert "translation: ('1.000000', '-2.000000', '0.000000')" in stp.stderr()
    assert "[static_transform_publisher_" in stp.stderr()


def test_stp_old_positional_forms_warn_and_publish(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    quaternion = spawn(standin("stp", "0", "0", "1", "0", "0", "1", "0", "base", "top"), "q")
    euler = spawn(
        standin("stp", "0.5", "0", "0", "0", "0", "3.141592653589793", "base", "flip"), "e"
    )
    for proc in (quaternion, euler):
        wait_for(started(proc, "Spinning until stopped"), 15, "stp to start")
        assert "Old-style arguments are deprecated" in proc.stderr()
    seen = tf_probe(spawn, {"want": {"/tf_static": ["top", "flip"]}})
    assert close(seen["/tf_static"]["top"]["q"], [0.0, 0.0, 1.0, 0.0])
    assert close(seen["/tf_static"]["top"]["xyz"], [0.0, 0.0, 1.0])
    # x y z yaw pitch roll: a roll of pi about x
    assert close(seen["/tf_static"]["flip"]["q"], [1.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize(
    ("argv", "error"),
    [
        ([], "Frame id must not be empty (give --frame-id FRAME_ID)"),
        (
            ["--frame-id", "a"],
            "Child frame id must not be empty (give --child-frame-id CHILD_FRAME_ID)",
        ),
        (["--frame-id", "a", "--child-frame-id", "b", "--x"], "Not enough arguments for --x"),
        (
            ["--x", "one", "--frame-id", "a", "--child-frame-id", "b"],
            "Failed to parse --x argument as float (got 'one')",
        ),
        (
            ["--qx", "0", "--yaw", "1", "--frame-id", "a", "--child-frame-id", "b"],
            "Cannot specify both quaternion and Euler rotations",
        ),
        (["1", "2", "3", "a", "b"], "Extra unparsed arguments on command-line: 1 2 3 a b"),
        (
            ["--x", "1", "0", "0", "0", "0", "0", "0", "a", "b"],
            "Cannot specify both new-style (flags) and old-style (arguments)",
        ),
    ],
)
def test_stp_bad_arguments_are_one_error_and_the_usage(argv: list[str], error: str) -> None:
    done = subprocess.run(
        standin("stp", *argv), capture_output=True, text=True, timeout=30, check=False
    )
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert (
        lines[0]
        == f"[ERROR] [static_transform_publisher]: error parsing command line arguments: {error}"
    )
    assert lines[1].startswith("usage: static_transform_publisher")
    assert "Traceback" not in done.stderr


def test_stp_same_parent_and_child_is_refused(spawn: Callable[..., Proc]) -> None:
    stp = spawn(standin("stp", "--frame-id", "a", "--child-frame-id", "a"), "stp")
    assert stp.popen.wait(timeout=20) == 1
    assert "cannot publish static transform from 'a' to 'a', exiting" in stp.stderr()
    assert "Traceback" not in stp.stderr()


def test_a_missing_tf2_msgs_is_named_when_static_transform_publisher_cannot_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from test_roslaunch import plan_of

    from mlaunch import standins
    from mlaunch.plan.errors import MlaunchError

    monkeypatch.setattr(standins, "NEEDS", {"stp": "mlaunch_test_no_such_module"})
    launch = tmp_path / "stp.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n\n\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([Node(package='tf2_ros',"
        " executable='static_transform_publisher',"
        " arguments=['--frame-id', 'a', '--child-frame-id', 'b'])])\n"
    )
    with pytest.raises(MlaunchError) as info:
        plan_of(str(launch))
    assert "package 'tf2_ros' not found" in str(info.value)
    assert (
        "(mlaunch's stand-in for it needs mlaunch_test_no_such_module: ./scripts/setup builds it)"
        in str(info.value)
    )
