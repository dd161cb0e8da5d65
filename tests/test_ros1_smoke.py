"""``mlaunch test`` on native ROS 1 runs: ready means every node of the file registered with the
ROS 1 master (asked over XML-RPC), with the verdicts, table and JUnit of ROS 2 runs."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import xmlrpc.client
from pathlib import Path

import pytest
from ports import free_port
from ros1tree import package_tree, requires_roslaunch

REPO = Path(__file__).resolve().parent.parent
NODES = (
    "/usr/lib/robot_state_publisher/robot_state_publisher",
    "/usr/lib/joint_state_publisher/joint_state_publisher",
    "/usr/lib/rosout/rosout",
)

pytestmark = [
    requires_roslaunch,
    pytest.mark.skipif(
        shutil.which("rosmaster") is None or not all(os.access(p, os.X_OK) for p in NODES),
        reason="Debian's rosmaster, rosout, robot_state_publisher, joint_state_publisher"
        " are not installed",
    ),
]

SMARTCAR_NODES = """<launch>
  <param name="robot_description"
         command="$(find xacro)/xacro '$(find smartcar_description)/urdf/smartcar.urdf.xacro'"/>
  <node name="joint_state_publisher" pkg="joint_state_publisher" type="joint_state_publisher"/>
  <group ns="car">
    <node name="robot_state_publisher" pkg="robot_state_publisher" type="state_publisher"/>
  </group>
</launch>
"""

SLEEPER = """<launch>
  <param name="robot_description"
         command="$(find xacro)/xacro '$(find smartcar_description)/urdf/smartcar.urdf.xacro'"/>
  <node name="joint_state_publisher" pkg="joint_state_publisher" type="joint_state_publisher"/>
  <node name="sleeper" pkg="sleepy" type="sleeper" ns="idle"/>
</launch>
"""


def master_answers(port: int) -> bool:
    try:
        xmlrpc.client.ServerProxy(f"http://localhost:{port}/").getPid("/t")
    except OSError:
        return False
    return True


def run_test(
    tmp_path: Path, launch: str, *options: str
) -> tuple[subprocess.CompletedProcess[str], int]:
    env = package_tree(tmp_path, extra=(REPO / "robots" / "smartcar_description",))
    sleepy = tmp_path / "src" / "sleepy"
    sleepy.mkdir()
    (sleepy / "package.xml").write_text(
        '<package format="2"><name>sleepy</name><version>0.0.0</version><description>t'
        "</description><maintainer email='t@e.st'>t</maintainer><license>BSD</license></package>"
    )
    program = sleepy / "sleeper"
    program.write_text("#!/bin/sh\nexec sleep 600\n")  # runs, never registers
    program.chmod(0o755)
    path = tmp_path / "src" / "nodes.launch"
    path.write_text(launch)
    port = free_port()
    env.update(ROS_MASTER_URI=f"http://localhost:{port}/", ROS_HOME=str(tmp_path / "ros"))
    argv = [sys.executable, "-m", "mlaunch", "test", str(path), "--ros1", *options]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=120, check=False)
    return done, port


def test_smartcar_nodes_pass_when_registered_with_the_master(tmp_path: Path) -> None:
    junit = tmp_path / "junit.xml"
    done, port = run_test(
        tmp_path,
        SMARTCAR_NODES,
        *("--hold", "1", "--timeout", "60", "--junit", str(junit)),
        *("--expect-service", "/car/robot_state_publisher/get_loggers"),
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    for node in ("/joint_state_publisher", "/car/robot_state_publisher", "/rosout"):
        line = next(x for x in done.stdout.splitlines() if f"node {node} " in x)
        assert "in the graph" in line, line
    service = next(x for x in done.stdout.splitlines() if "service /car/" in x)
    assert "offered" in service and "not offered" not in service, service  # the master's list
    cases = {c.get("name", ""): c for c in ET.parse(junit).getroot().iter("testcase")}
    assert any("/car/robot_state_publisher" in name for name in cases), cases
    assert not any(c.find("failure") is not None for c in cases.values())
    assert not master_answers(port)  # the master mlaunch started ended with the run


def test_a_node_that_never_registers_fails_naming_it(tmp_path: Path) -> None:
    done, port = run_test(tmp_path, SLEEPER, "--timeout", "6")
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    failed = [x for x in done.stdout.splitlines() if "node /idle/sleeper" in x]
    assert failed and "not in the graph" in failed[0], out
    assert "/joint_state_publisher" in failed[0]  # the nodes that did register are named
    # the report shows the failed node's own output (the process started after the plan)
    assert re.search(r"last output of sleeper-\d+:\n  \| \(no output\)", done.stdout), out
    passed = next(x for x in done.stdout.splitlines() if "node /joint_state_publisher " in x)
    assert "in the graph" in passed and "not" not in passed, passed
    assert not master_answers(port)


def test_lifecycle_checks_are_refused_on_a_native_run(tmp_path: Path) -> None:
    done, _ = run_test(tmp_path, SLEEPER, "--expect-lifecycle", "/idle/sleeper")
    assert done.returncode == 2, done.stdout + done.stderr
    assert "a native ROS 1 run checks process, output, node, service, topic" in done.stderr


def test_topics_are_read_through_rospy(tmp_path: Path) -> None:
    """joint_state_publisher publishes /joint_states at 10 Hz (its default rate); nothing
    publishes /odom here: the row names the topics the master has instead."""
    done, port = run_test(
        tmp_path,
        SMARTCAR_NODES,
        *("--expect-topic", "/joint_states:5", "--expect-topic", "/odom", "--timeout", "20"),
    )
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    rate = next(x for x in done.stdout.splitlines() if "topic /joint_states " in x)
    assert re.search(r"\d+\.\d Hz over", rate) and "too" not in rate, rate
    odom = next(x for x in done.stdout.splitlines() if "topic /odom" in x)
    assert "not in the graph" in odom, odom
    assert not master_answers(port)
    # no reader outlives the run (each ends when mlaunch closes its stdin)
    probes = [
        p
        for p in os.listdir("/proc")
        if p.isdigit() and _cmdline(p).endswith(f"ros1_topic_probe.py\0{'/odom'}\0")
    ]
    assert not probes


def _cmdline(pid: str) -> str:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().decode("utf-8", "replace")
    except OSError:
        return ""
