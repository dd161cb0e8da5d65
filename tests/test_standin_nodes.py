"""robot_state_publisher and joint_state_publisher stand-ins, run as real processes.

Each test starts the stand-in with the command line a launch would give it, and a probe child
(``sys.executable -c PROBE``) that subscribes, queries parameters or publishes /clock and prints
what it saw as JSON lines.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import requires_rclpy
from procutil import wait_for

pytestmark = [requires_rclpy, pytest.mark.timeout(60)]

URDF = """<?xml version="1.0"?>
<robot name="probe_bot">
  <link name="base_link"><visual><geometry><box size="0.4 0.3 0.1"/></geometry></visual></link>
  <link name="left_wheel"/>
  <link name="right_wheel"/>
  <link name="arm"/>
  <link name="laser"/>
  <joint name="left_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="left_wheel"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="right_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="right_wheel"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="arm_joint" type="revolute">
    <parent link="base_link"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="0.5" upper="1.5" effort="1" velocity="1"/>
  </joint>
  <joint name="laser_joint" type="fixed">
    <parent link="base_link"/><child link="laser"/><origin xyz="0.1 0 0.2"/>
  </joint>
</robot>
"""

# The probe: one child process that does what a spec asks and prints JSON lines.
PROBE = textwrap.dedent(
    r"""
    import json, sys, time
    import rclpy
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    spec = json.loads(sys.argv[1])
    rclpy.init()
    node = Node("probe")
    deadline = time.monotonic() + spec.get("timeout", 20)

    def out(**fields):
        print(json.dumps(fields), flush=True)

    def spin_until(pred):
        while not pred():
            if time.monotonic() > deadline:
                out(kind="timeout")
                sys.exit(3)
            rclpy.spin_once(node, timeout_sec=0.05)

    if "params_of" in spec:
        from rcl_interfaces.srv import GetParameters
        from rclpy.parameter import parameter_value_to_python

        client = node.create_client(GetParameters, spec["params_of"] + "/get_parameters")
        spin_until(client.service_is_ready)
        future = client.call_async(GetParameters.Request(names=spec["names"]))
        spin_until(future.done)
        values = [parameter_value_to_python(v) for v in future.result().values]
        out(kind="params", values=dict(zip(spec["names"], values)))

    if spec.get("latched"):
        from std_msgs.msg import String

        got = []
        qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
        node.create_subscription(String, spec["latched"], lambda m: got.append(m.data), qos)
        spin_until(lambda: got)
        out(kind="latched", topic=spec["latched"], data=got[0])

    if spec.get("publish_joints"):
        from sensor_msgs.msg import JointState

        pub = node.create_publisher(JointState, spec["publish_joints"], 10)
        spin_until(lambda: pub.get_subscription_count())
        # each batch of names 10 times, in order: a later batch seen means the earlier one was
        for names in spec["batches"]:
            for _ in range(10):
                pub.publish(JointState(name=names, position=[0.5] * len(names)))
                until = time.monotonic() + 0.02
                spin_until(lambda: time.monotonic() > until)
        out(kind="published")

    if spec.get("joint_states"):
        from sensor_msgs.msg import JointState

        got = []
        sub = node.create_subscription(JointState, spec["joint_states"], got.append, 10)
        if spec.get("clock") is not None:
            from rosgraph_msgs.msg import Clock

            clock = node.create_publisher(Clock, "/clock", 10)
            # Both directions matched, then a quiet spell: anything published now would have
            # been stamped without a clock.
            spin_until(lambda: sub.get_publisher_count() and clock.get_subscription_count())
            quiet = time.monotonic() + 0.5
            spin_until(lambda: time.monotonic() > quiet)
            out(kind="before_clock", count=len(got))
            tick = Clock()
            tick.clock.sec = spec["clock"]

            def advance():
                # sim time moves 10 ms per tick: timers on the node clock need it to move
                clock.publish(tick)
                tick.clock.nanosec = min(tick.clock.nanosec + 10_000_000, 999_000_000)

            node.create_timer(0.05, advance)
        spin_until(lambda: got)
        m = got[0]
        out(kind="joint_states", name=list(m.name), position=list(m.position),
            velocity=list(m.velocity), stamp=[m.header.stamp.sec, m.header.stamp.nanosec])
    node.destroy_node()
    rclpy.shutdown()
    """
)


class Proc:
    """A child process with its output in files, so a chatty node never blocks on a pipe."""

    def __init__(self, argv: list[str], env: dict[str, str], workdir: Path, name: str) -> None:
        self.out_path = workdir / f"{name}.out"
        self.err_path = workdir / f"{name}.err"
        with open(self.out_path, "wb") as out, open(self.err_path, "wb") as err:
            self.popen = subprocess.Popen(argv, env=env, stdout=out, stderr=err)

    def stdout(self) -> str:
        return self.out_path.read_text(errors="replace")

    def stderr(self) -> str:
        return self.err_path.read_text(errors="replace")

    def stop(self) -> None:
        if self.popen.poll() is None:
            self.popen.terminate()
            try:
                self.popen.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait()


@pytest.fixture
def spawn(ros_env: dict[str, str], tmp_path: Path) -> Iterator[Callable[..., Proc]]:
    """Start children in the test's ROS domain; every one is stopped when the test ends."""
    started: list[Proc] = []

    def start(argv: list[str], name: str) -> Proc:
        proc = Proc(argv, ros_env, tmp_path, name)
        started.append(proc)
        return proc

    try:
        yield start
    finally:
        for proc in started:
            proc.stop()


def standin(module: str, *args: str) -> list[str]:
    return [sys.executable, "-m", f"mlaunch.standins.{module}", *args]


def params_file(tmp_path: Path, values: dict[str, Any], node: str = "/**") -> str:
    """A ROS 2 parameter file like the one launch writes for ``parameters=[{...}]``."""
    path = tmp_path / f"params_{len(list(tmp_path.glob('params_*')))}.yaml"
    path.write_text(json.dumps({node: {"ros__parameters": values}}))  # JSON is YAML
    return str(path)


def probe(spawn: Callable[..., Proc], spec: dict[str, Any]) -> list[dict[str, Any]]:
    """Run the probe to completion and return its JSON lines."""
    proc = spawn([sys.executable, "-c", PROBE, json.dumps(spec)], "probe")
    try:
        proc.popen.wait(timeout=spec.get("timeout", 20) + 10)
    except subprocess.TimeoutExpired:
        proc.stop()
    lines = [json.loads(line) for line in proc.stdout().splitlines() if line.startswith("{")]
    assert proc.popen.returncode == 0, f"probe failed: {lines} {proc.stderr()[-2000:]}"
    return lines


def started(proc: Proc, marker: str) -> Callable[[], bool]:
    """True once ``marker`` is in the process's log; fails at once if it died instead."""

    def check() -> bool:
        if proc.popen.poll() is not None:
            raise AssertionError(f"exited {proc.popen.returncode}: {proc.stderr()[-2000:]}")
        return marker in proc.stderr()

    return check


# ---------------------------------------------------------------- robot_state_publisher


def test_rsp_latches_description_for_a_late_subscriber(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    # Every parameter the real node declares, from a parameter file as launch writes it.
    params = params_file(
        tmp_path,
        {
            "robot_description": URDF,
            "publish_frequency": 50,  # an int for a double: YAML writes it so
            "ignore_timestamp": True,
            "frame_prefix": "r/",
            "use_sim_time": False,
        },
    )
    rsp = spawn(standin("rsp", "--ros-args", "--params-file", params), "rsp")
    wait_for(started(rsp, "Robot initialized"), 15, "rsp to start")
    # Subscribed only now, after the one publication: it still arrives (transient local).
    lines = probe(
        spawn,
        {
            "latched": "/robot_description",
            "params_of": "/robot_state_publisher",
            "names": ["publish_frequency", "ignore_timestamp", "frame_prefix"],
        },
    )
    kinds = {line["kind"]: line for line in lines}
    assert kinds["latched"]["data"] == URDF
    assert kinds["params"]["values"] == {
        "publish_frequency": 50.0,
        "ignore_timestamp": True,
        "frame_prefix": "r/",
    }
    assert "got segment left_wheel" in rsp.stderr()
    assert rsp.popen.poll() is None


def test_rsp_namespace_moves_the_topic(spawn: Callable[..., Proc], tmp_path: Path) -> None:
    params = params_file(tmp_path, {"robot_description": URDF})
    argv = standin("rsp", "--ros-args", "-r", "__ns:=/r1", "--params-file", params)
    rsp = spawn([*argv, "-p", "use_sim_time:=True"], "rsp")
    wait_for(started(rsp, "Robot initialized"), 15, "rsp to start")
    lines = probe(
        spawn,
        {
            "latched": "/r1/robot_description",
            "params_of": "/r1/robot_state_publisher",
            "names": ["use_sim_time"],
        },
    )
    kinds = {line["kind"]: line for line in lines}
    assert kinds["latched"]["data"] == URDF
    assert kinds["params"]["values"] == {"use_sim_time": True}
    assert "[r1.robot_state_publisher]" in rsp.stderr()


def test_rsp_names_unknown_joints_once(spawn: Callable[..., Proc], tmp_path: Path) -> None:
    params = params_file(tmp_path, {"robot_description": URDF})
    rsp = spawn(standin("rsp", "--ros-args", "--params-file", params), "rsp")
    wait_for(started(rsp, "Robot initialized"), 15, "rsp to start")
    batches = [["left_wheel_joint", "mystery_joint"], ["sentinel_joint"]]
    probe(spawn, {"publish_joints": "/joint_states", "batches": batches})
    wait_for(lambda: "'sentinel_joint'" in rsp.stderr(), 10, "rsp to name the sentinel joint")
    warnings = [line for line in rsp.stderr().splitlines() if "mystery_joint" in line]
    assert len(warnings) == 1, warnings
    assert "not in robot 'probe_bot'" in warnings[0]
    assert "left_wheel_joint" not in rsp.stderr()


@pytest.mark.parametrize(
    ("description", "expected"),
    [
        (
            URDF.replace(
                '<parent link="base_link"/><child link="laser"/>',
                '<parent link="nowhere"/><child link="laser"/>',
            ),
            "joint 'laser_joint': parent link 'nowhere' does not exist",
        ),
        (URDF.replace('type="fixed"', 'type="welded"'), "has type 'welded'"),
        ("", "parameter 'robot_description' is empty or not set"),
    ],
)
def test_rsp_refuses_a_broken_urdf(
    spawn: Callable[..., Proc], tmp_path: Path, description: str, expected: str
) -> None:
    params = params_file(tmp_path, {"robot_description": description})
    rsp = spawn(standin("rsp", "--ros-args", "--params-file", params), "rsp")
    assert rsp.popen.wait(timeout=20) == 1
    errors = [line for line in rsp.stderr().splitlines() if "ERROR" in line]
    assert len(errors) == 1, errors  # one line
    assert expected in errors[0]
    assert "Traceback" not in rsp.stderr()


# ---------------------------------------------------------------- joint_state_publisher


def test_jsp_publishes_default_positions_for_movable_joints(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    params = params_file(
        tmp_path,
        {"robot_description": URDF, "rate": 20, "zeros": {"right_wheel_joint": 0.25}},
        node="joint_state_publisher",
    )
    jsp = spawn(standin("jsp", "--ros-args", "--params-file", params), "jsp")
    wait_for(started(jsp, "publishing joints"), 15, "jsp to start")
    (line,) = probe(spawn, {"joint_states": "/joint_states"})
    # fixed laser_joint left out; document order; arm limited to [0.5, 1.5] starts mid-range
    assert line["name"] == ["left_wheel_joint", "right_wheel_joint", "arm_joint"]
    assert line["position"] == [0.0, 0.25, 1.0]
    assert line["velocity"] == []
    assert line["stamp"][0] > 1_000_000_000  # wall clock time, not zero


def test_jsp_reads_the_description_topic_and_waits_for_sim_time(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    # No robot_description parameter: the URDF comes from rsp's latched topic. use_sim_time is
    # set the way launch's Node(parameters=[{'use_sim_time': True}]) can also pass it, as -p.
    rsp_params = params_file(tmp_path, {"robot_description": URDF})
    spawn(standin("rsp", "--ros-args", "--params-file", rsp_params), "rsp")
    argv = standin("jsp", "--ros-args", "-p", "use_sim_time:=True", "-r", "__node:=jsp")
    jsp = spawn(argv, "jsp")
    wait_for(started(jsp, "robot 'probe_bot': publishing joints"), 20, "jsp to read the URDF")
    assert "use_sim_time is true: waiting for /clock" in jsp.stderr()
    lines = probe(
        spawn,
        {
            "params_of": "/jsp",
            "names": ["use_sim_time"],
            "joint_states": "joint_states",
            "clock": 42,
        },
    )
    kinds = {line["kind"]: line for line in lines}
    assert kinds["params"]["values"] == {"use_sim_time": True}
    assert kinds["before_clock"]["count"] == 0  # nothing stamped before /clock
    assert kinds["joint_states"]["stamp"][0] == 42
    assert kinds["joint_states"]["name"] == ["left_wheel_joint", "right_wheel_joint", "arm_joint"]


def test_jsp_takes_a_urdf_file_argument_and_rejects_a_missing_one(
    spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    missing = str(tmp_path / "missing.urdf")
    jsp = spawn(standin("jsp", missing, "--ros-args", "-r", "__node:=j"), "jsp")
    assert jsp.popen.wait(timeout=20) == 1
    assert f"cannot read URDF file {missing!r}" in jsp.stderr()
