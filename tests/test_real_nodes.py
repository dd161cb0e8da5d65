"""mlaunch on real ROS 2 C++ programs, where ``scripts/setup --real-nodes`` built them (CI does).

The build installs rclcpp's component containers, tf2_ros, robot_state_publisher and the demo
nodes into the venv's ament prefix; these tests put that prefix on AMENT_PREFIX_PATH (as
activating the venv does) and check that the real programs run in place of the stand-ins: the
jtbot seed's robot_state_publisher gives the same TF tree as the stand-in, composable nodes load
into the real container under ``mlaunch`` and ``mlaunch test``, and a launch_testing file on the
real talker and listener passes under both launch_test runners.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import VENV_PREFIX, requires_rclpy
from procutil import REPO, Running, clean_env, mlaunch
from test_launch_testing import outcomes, run_launch_test

HERE = Path(__file__).resolve().parent / "real_nodes"
PREFIX = Path(VENV_PREFIX)
REAL_PROGRAMS = (
    "rclcpp_components/component_container",
    "robot_state_publisher/robot_state_publisher",
    "tf2_ros/static_transform_publisher",
    "demo_nodes_cpp/talker",
)
MISSING = [name for name in REAL_PROGRAMS if not os.access(PREFIX / "lib" / name, os.X_OK)]
requires_real_nodes = pytest.mark.skipif(
    bool(MISSING),
    reason=f"the real ROS 2 nodes are not built ({PREFIX}/lib/{MISSING[0] if MISSING else ''}"
    " is missing): run scripts/setup --real-nodes [DIR] (CI always builds them)",
)
pytestmark = [requires_rclpy, requires_real_nodes, pytest.mark.timeout(120)]


def env_for(ros_env: dict[str, str], tmp_path: Path, *, real: bool) -> dict[str, str]:
    """The test's ROS domain, with the venv's ament prefix first when ``real``."""
    env = clean_env(**ros_env)
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    others = [e for e in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if e]
    env["AMENT_PREFIX_PATH"] = os.pathsep.join(([str(PREFIX)] if real else []) + others)
    return env


def test_the_seed_resolves_to_the_real_programs(ros_env: dict[str, str], tmp_path: Path) -> None:
    """--print: the real robot_state_publisher and container; simulator and viewer stay
    stand-ins (there is no Gazebo or RViz)."""
    env = env_for(ros_env, tmp_path, real=True)
    for launch, real in (
        ("jtbot_sim.launch.py", "robot_state_publisher/robot_state_publisher"),
        ("jtbot_composed.launch.py", "rclcpp_components/component_container"),
    ):
        done = subprocess.run(
            mlaunch(str(REPO / "launches" / launch), "--print"),
            capture_output=True, text=True, env=env, timeout=60,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        assert str(PREFIX / "lib" / real) in done.stdout, done.stdout
        assert "mlaunch.standins.viewer" in done.stdout, done.stdout
        assert "mlaunch.standins.rsp" not in done.stdout, done.stdout


def tf_tree(env: dict[str, str], tmp_path: Path) -> tuple[dict[str, Any], str]:
    """The jtbot TF tree (parents, topics, poses) with joint_state_publisher's zero joints, and
    mlaunch's output."""
    run = Running(
        mlaunch(str(REPO / "launches" / "jtbot_display.launch.py"), "rviz:=false"),
        env=env, cwd=str(tmp_path),
    )  # fmt: skip
    try:
        done = subprocess.run(
            [sys.executable, str(REPO / "tests" / "tf_tree_probe.py"), "base_footprint", "30"],
            capture_output=True, text=True, env=env, timeout=60,
        )  # fmt: skip
        run.signal(signal.SIGINT)
        code = run.finish(timeout=20)
    finally:
        run.kill()
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:] + run.text[-3000:]
    assert code == 130, run.text[-3000:]
    tree: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return {key: tree[key] for key in ("parents", "topics", "poses")}, run.text


def test_jtbot_tf_tree_of_the_real_state_publisher_equals_the_standins(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    (tmp_path / "real").mkdir()
    (tmp_path / "standin").mkdir()
    real, real_log = tf_tree(env_for(ros_env, tmp_path / "real", real=True), tmp_path / "real")
    standin, standin_log = tf_tree(
        env_for(ros_env, tmp_path / "standin", real=False), tmp_path / "standin"
    )
    assert "robot_state_publisher: not installed" not in real_log, real_log
    assert "robot_state_publisher: not installed" in standin_log, standin_log
    assert real["parents"] == standin["parents"] and real["topics"] == standin["topics"]
    ours, theirs = real["poses"], standin["poses"]
    differing = {k: (ours.get(k), theirs.get(k)) for k in ours.keys() | theirs.keys()}
    assert not {k: pair for k, pair in differing.items() if pair[0] != pair[1]}
    assert real["topics"]["left_wheel_link"] == "/tf"
    assert real["topics"]["camera_depth_frame"] == "/tf_static"


def test_composable_nodes_load_into_the_real_container(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """`mlaunch`: the demo's talker and listener components load through LoadNode and talk."""
    env = env_for(ros_env, tmp_path, real=True)
    run = Running(mlaunch(str(HERE / "composition.launch.py")), env=env, cwd=str(tmp_path))
    try:
        run.wait_for(r"Loaded node '/talker' in container '/demo_container'", timeout=60)
        run.wait_for(r"Loaded node '/listener' in container '/demo_container'", timeout=60)
        run.wait_for(r"I heard: \[Hello World: \d+\]", timeout=30)
        run.signal(signal.SIGINT)
        assert run.finish(timeout=20) == 130, run.text[-3000:]
    finally:
        run.kill()
    assert "not installed" not in run.text, run.text[-3000:]


TYPED = """
from launch import LaunchDescription
from launch_ros.actions import LoadComposableNodes, Node
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    talker = 'composition::Talker'
    return LaunchDescription([
        Node(package='rclcpp_components', executable='component_container', name='cbox'),
        LoadComposableNodes(target_container='/cbox', composable_node_descriptions=[
            ComposableNode(package='composition', plugin=talker, name='typed',
                           parameters=[{'use_sim_time': True, 'n': 3, 'xs': [1.5, 2.0],
                                        'big': ['x' * 100] * 1000}],
                           extra_arguments=[{'use_intra_process_comms': True}]),
            ComposableNode(package='composition', plugin=talker, name='badly_typed',
                           extra_arguments=[{'use_intra_process_comms': 'yes'}]),
            ComposableNode(package='composition', plugin='composition::Nope', name='nope'),
        ]),
    ])
"""


@pytest.mark.parametrize("loader", ["", "rclpy"])
def test_the_real_container_gets_typed_values_and_says_why_it_refuses(
    loader: str, ros_env: dict[str, str], tmp_path: Path
) -> None:
    """rclcpp's own component manager reads the request (~100 kB: in fragments over RTPS): a
    bool parameter arrives as a bool (the node's use_sim_time), a string where it reads a bool is refused with rclcpp's message,
    an unknown plugin with its loader's; the same over RTPS (the default) and rclpy."""
    env = env_for(ros_env, tmp_path, real=True)
    if loader:
        env["MLAUNCH_LOADER"] = loader
    path = tmp_path / "typed.launch.py"
    path.write_text(TYPED)
    run = Running(mlaunch(str(path)), env=env, cwd=str(tmp_path))
    try:
        run.wait_for(r"Loaded node '/typed' in container '/cbox'", timeout=60)
        run.wait_for(
            r"Failed to load node 'badly_typed' of type 'composition::Talker' in container"
            r" '/cbox': Extra component argument 'use_intra_process_comms' must be a boolean",
            timeout=30,
        )
        run.wait_for(
            r"Failed to load node 'nope' of type 'composition::Nope' in container '/cbox':"
            r" Failed to find class with the requested plugin name",
            timeout=30,
        )
        assert parameter_of("/typed", "use_sim_time", ros_env) == (1, True)  # BOOL
        run.signal(signal.SIGINT)
        assert run.finish(timeout=20) == 130, run.text[-3000:]
    finally:
        run.kill()


def parameter_of(node: str, name: str, ros_env: dict[str, str]) -> tuple[int, Any]:
    """(type, value) of a node's parameter, through its get_parameters service."""
    import rclpy
    from rcl_interfaces.srv import GetParameters
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        probe = Node("param_probe", context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(probe)
        client = probe.create_client(GetParameters, f"{node}/get_parameters")
        assert client.wait_for_service(timeout_sec=20.0)
        future = client.call_async(GetParameters.Request(names=[name]))
        executor.spin_until_future_complete(future, timeout_sec=20.0)
        (value,) = future.result().values
        executor.shutdown()
        return value.type, value.bool_value
    finally:
        context.try_shutdown()


def test_mlaunch_test_on_the_real_container(ros_env: dict[str, str], tmp_path: Path) -> None:
    """`mlaunch test`: the components are in the graph and /chatter flows; the composed jtbot
    (robot_state_publisher's component in the real container) is ready too."""
    env = env_for(ros_env, tmp_path, real=True)
    for launch, expectations in (
        (HERE / "composition.launch.py", ["--expect-topic", "/chatter"]),
        (
            REPO / "launches" / "jtbot_composed.launch.py",
            [
                "rviz:=false",
                "--expect-topic",
                "/tf_static",
                "--expect-node",
                "/robot_state_publisher",
            ],
        ),
    ):
        junit = tmp_path / f"{launch.name}.xml"
        done = subprocess.run(
            mlaunch("test", str(launch), *expectations, "--hold", "1", "--junit", str(junit)),
            capture_output=True, text=True, env=env, timeout=90,
        )  # fmt: skip
        assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
        assert 'failures="0"' in junit.read_text()
        assert "component_container: not installed" not in done.stdout + done.stderr


@pytest.mark.parametrize("runner", ["launch_test", "mlaunch test"])
def test_launch_testing_on_the_real_talker_and_listener(
    runner: str, ros_env: dict[str, str], tmp_path: Path
) -> None:
    program = [str(Path(sys.executable).with_name("launch_test"))]
    argv = program if runner == "launch_test" else mlaunch("test")
    report = tmp_path / "report.xml"
    done = run_launch_test(
        [*argv, str(HERE / "talker_listener.test.py")],
        report,
        env_for(ros_env, tmp_path, real=True),
    )
    results = outcomes(report)
    assert set(results.values()) == {"passed"} and len(results) == 3, done.stdout + done.stderr
    assert done.returncode == 0


def test_ros1_static_transform_publisher_runs_the_real_tf2_ros_one(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    env = env_for(ros_env, tmp_path, real=True)
    launch = str(HERE / "static_tf.launch")
    shown = subprocess.run(
        mlaunch(launch, "--print"), capture_output=True, text=True, env=env, timeout=60
    )
    assert str(PREFIX / "lib/tf2_ros/static_transform_publisher") in shown.stdout, shown.stdout
    done = subprocess.run(
        mlaunch("test", launch, "--expect-topic", "/tf_static", "--hold", "1"),
        capture_output=True, text=True, env=env, timeout=90,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "not installed" not in done.stdout + done.stderr


@pytest.mark.slow
def test_mlaunch_test_passes_on_the_seed_with_the_real_state_publisher(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    env = env_for(ros_env, tmp_path, real=True)
    done = subprocess.run(
        mlaunch(
            "test", str(REPO / "launches" / "jtbot_sim.launch.py"),
            "--allow-exit", "spawn_entity.py",
            "--expect-topic", "/tf", "--expect-topic", "/tf_static", "--expect-topic", "/odom",
            "--expect-node", "/robot_state_publisher", "--hold", "1",
        ),
        capture_output=True, text=True, env=env, timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    out = done.stdout + done.stderr
    assert "robot_state_publisher: not installed" not in out, out[-3000:]
    assert "[gazebo-1] mlaunch sim: spawned model 'jtbot'" in out, out[-3000:]  # the stand-in
