"""The launch panel with ROS: on the viewer's page (the jtbot's run seen and steered from the
address the viewer prints), and a composable node unloaded and loaded again from the page, in
headless Chromium (issue 36)."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from browser import Browser, available
from conftest import requires_rclpy
from procutil import REPO, Running, mlaunch, run_mlaunch
from test_dashboard import assert_refuses_strangers, download_evidence

OPEN = r"viewer: open http://127\.0\.0\.1:(\d+)/"
JTBOT = ("gazebo-1", "robot_state_publisher-2", "spawn_entity.py-3", "rviz2-4")
# The panel is the viewer page's iframe, of the same origin: its document is reachable.
PANEL = "document.getElementById('launch').contentDocument"


def row(label: str, field: str) -> str:
    """Script reading one data field of ``label``'s row in the panel."""
    return f"{PANEL}.querySelector('tr[data-label=\"{label}\"]').dataset.{field}"


@requires_rclpy
@pytest.mark.timeout(150)
@pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")
def test_the_viewer_page_shows_the_jtbot_run_and_restarts_a_node(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    env = {**ros_env, "ROS_LOG_DIR": str(tmp_path / "logs"), "NO_COLOR": "1"}
    env.pop("MLAUNCH_VIEWER_PORT", None)
    launch = str(REPO / "launches" / "jtbot_sim.launch.py")
    run = Running(mlaunch(launch), env=env, cwd=str(tmp_path))
    try:
        port = int(run.wait_for(OPEN, 60).group(1))
        with Browser(tmp_path / "profile", width=1600, height=900) as browser:
            page = browser.open(f"http://127.0.0.1:{port}/")
            page.wait("document.body.classList.contains('with-panel')", 30, "the launch panel")
            # every jtbot process, the simulator with live CPU
            page.wait(
                f"{PANEL}.body.dataset.updates > 1 && Number({row('gazebo-1', 'cpu')}) > 0",
                60,
                "the simulator's CPU in the panel",
            )
            labels = page.eval(
                f"[...{PANEL}.querySelectorAll('#procs tbody tr')].map(r => r.dataset.label)"
            )
            assert tuple(labels) == JTBOT
            before = int(page.eval(row("robot_state_publisher-2", "pid")))
            frame = "document.getElementById('launch').contentWindow"
            clicked = page.eval(
                f"(() => {{ const b = {PANEL}.querySelector("
                '\'tr[data-label="robot_state_publisher-2"] button[data-op="restart"]\');'
                " b.click(); return true; })()"
            )
            assert clicked
            answer = json.loads(
                page.wait(f"{frame}.document.body.dataset.lastControl", 60, "the restart")
            )
            assert answer["ok"] and answer["pid"] not in (0, before), answer
            done = run_mlaunch("ctl", "list", "--json", env=env, timeout=30)
            listed: dict[str, Any] = {p["label"]: p for p in json.loads(done.stdout)["processes"]}
            assert listed["robot_state_publisher-2"]["pid"] == answer["pid"]
            assert listed["robot_state_publisher-2"]["restarts"] == 1
            page.wait(
                f"{row('robot_state_publisher-2', 'pid')} == {answer['pid']}", 15, "the new pid"
            )
        # through the viewer's address, the same refusals as the panel's own port
        assert_refuses_strangers(port, "robot_state_publisher-2")
        evidence = json.loads(download_evidence(port)["processes.json"])
        assert tuple(sorted(r["label"] for r in evidence)) == tuple(sorted(JTBOT))
        run.signal(signal.SIGINT)
        assert run.finish(60) == 130
    finally:
        if run.proc.poll() is None:
            run.kill()


LIST_NODES = """
import sys, rclpy
from composition_interfaces.srv import ListNodes
rclpy.init()
node = rclpy.create_node("_list_nodes_probe")
client = node.create_client(ListNodes, sys.argv[1])
if not client.wait_for_service(timeout_sec=20):
    sys.exit("no service")
future = client.call_async(ListNodes.Request())
rclpy.spin_until_future_complete(node, future, timeout_sec=20)
print(" ".join(future.result().full_node_names))
"""


def container_nodes(env: dict[str, str]) -> list[str]:
    """The nodes /jtbot_container says it holds (its list_nodes service)."""
    done = subprocess.run(
        [sys.executable, "-c", LIST_NODES, "/jtbot_container/_container/list_nodes"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


@requires_rclpy
@pytest.mark.timeout(150)
@pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")
def test_a_composable_node_unloaded_from_the_page_is_gone_from_its_container(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    env = {**ros_env, "ROS_LOG_DIR": str(tmp_path / "logs"), "NO_COLOR": "1"}
    launch = str(REPO / "launches" / "jtbot_composed.launch.py")
    run = Running(mlaunch(launch, "rviz:=false", "--dashboard"), env=env, cwd=str(tmp_path))
    node = 'tr[data-node="/robot_state_publisher"]'
    try:
        url = run.wait_for(r"dashboard: open (http://127\.0\.0\.1:\d+/launch/)", 60).group(1)
        with Browser(tmp_path / "profile") as browser:
            page = browser.open(url)
            state = f"document.querySelector('{node}')?.dataset.state"
            page.wait(f"{state} == 'loaded'", 60, "the component loaded")
            assert container_nodes(env) == ["/robot_state_publisher"]
            page.click(f'{node} button[data-op="unload"]')
            answer = json.loads(page.wait("document.body.dataset.lastControl", 30, "unload"))
            assert answer["ok"] and answer["op"] == "unload", answer
            page.wait(f"{state} == 'unloaded'", 15, "the component unloaded")
            assert container_nodes(env) == []
            run.wait_for(r"Unloaded node '/robot_state_publisher' from container", 10)
            run.wait_for(r"unload asked by the user \(the launch panel\)", 10)
            page.eval("delete document.body.dataset.lastControl")
            page.click(f'{node} button[data-op="load"]')
            answer = json.loads(page.wait("document.body.dataset.lastControl", 60, "load"))
            assert answer["ok"] and answer["op"] == "load", answer
            page.wait(f"{state} == 'loaded'", 15, "the component loaded again")
            assert container_nodes(env) == ["/robot_state_publisher"]
        run.signal(signal.SIGINT)
        assert run.finish(60) == 130
    finally:
        if run.proc.poll() is None:
            run.kill()


LIFECYCLE = f"""import sys
from launch import LaunchDescription
from launch_ros.actions import LifecycleNode
NODE = {str(REPO / "tests" / "nodes" / "lifecycle_node.py")!r}
def generate_launch_description():
    return LaunchDescription([
        LifecycleNode(executable=sys.executable, arguments=[NODE], name="camera",
                      namespace="robot", exec_name="camera", output="screen", autostart=True),
    ])
"""


@requires_rclpy
@pytest.mark.timeout(150)
@pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")
def test_a_lifecycle_transition_asked_from_the_page_reaches_the_node(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    path = tmp_path / "camera.launch.py"
    path.write_text(LIFECYCLE)
    env = {**ros_env, "ROS_LOG_DIR": str(tmp_path / "logs"), "NO_COLOR": "1"}
    run = Running(mlaunch(str(path), "--dashboard"), env=env, cwd=str(tmp_path))
    node = 'tr[data-lifecycle="/robot/camera"]'
    state = f"document.querySelector('{node}')?.dataset.state"
    try:
        url = run.wait_for(r"dashboard: open (http://127\.0\.0\.1:\d+/launch/)", 60).group(1)
        run.wait_for(r"activate of /robot/camera succeeded", 60)
        with Browser(tmp_path / "profile") as browser:
            page = browser.open(url)
            page.wait(f"{state} == 'active'", 30, "the node active in the panel")
            page.click(f'{node} button[data-op="deactivate"]')
            answer = json.loads(page.wait("document.body.dataset.lastControl", 30, "deactivate"))
            assert answer["ok"] and answer["op"] == "deactivate", answer
            # the node itself says it went through the transition (it prints each one)
            run.wait_for(r"\[camera-1\] transition deactivate: success", 15)
            run.wait_for(r"deactivate asked by the user \(the launch panel\)", 5)
            page.wait(f"{state} == 'inactive'", 15, "the node inactive in the panel")
            page.eval("delete document.body.dataset.lastControl")
            page.click(f'{node} button[data-op="activate"]')
            answer = json.loads(page.wait("document.body.dataset.lastControl", 30, "activate"))
            assert answer["ok"], answer
            page.wait(f"{state} == 'active'", 15, "the node active again")
        assert run.text.count("[camera-1] transition activate: success") >= 1
        run.wait_for(r"(?s)deactivate: success.*\[camera-1\] transition activate: success", 15)
        run.signal(signal.SIGINT)
        assert run.finish(60) == 130
    finally:
        if run.proc.poll() is None:
            run.kill()
