"""``<machine>`` in native ROS 1 runs: a node that names a machine runs there over ssh (the
private sshd's ``mltest`` alias), with roslaunch's master and namespace; one whose machine is
this computer runs here."""

from __future__ import annotations

import os
import signal
import sys
import xmlrpc.client
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import sshd as sshd_server
from ports import free_port
from procutil import Running, wait_for
from ros1tree import package_tree, requires_roslaunch
from sshd import HOST_ALIAS, Server
from test_ros1_smoke import NODES

REPO = Path(__file__).resolve().parent.parent

pytestmark = [
    requires_roslaunch,
    pytest.mark.skipif(
        not all(os.access(p, os.X_OK) for p in NODES), reason="Debian's ROS 1 nodes are missing"
    ),
]

LAUNCH = """<launch>
  <machine name="far" address="{alias}" env-loader="{loader}" timeout="20"/>
  <machine name="here" address="localhost"/>
  <arg name="model" default="$(find smartcar_description)/urdf/smartcar.urdf.xacro"/>
  <param name="robot_description" command="$(find xacro)/xacro '$(arg model)'"/>
  <group ns="away">
    <param name="robot_description" command="$(find xacro)/xacro '$(arg model)'"/>
    <node machine="far" name="joint_state_publisher" pkg="joint_state_publisher"
          type="joint_state_publisher"/>
  </group>
  <node machine="here" name="robot_state_publisher" pkg="robot_state_publisher"
        type="robot_state_publisher"/>
</launch>
"""


@pytest.fixture(scope="module")
def sshd(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    yield from sshd_server.serve(tmp_path_factory)


def node_pid(port: int, name: str) -> int | None:
    """The pid of a node registered with the master (asked of the node itself), or None."""
    master: Any = xmlrpc.client.ServerProxy(f"http://localhost:{port}/")
    try:
        code, _, uri = master.lookupNode("/test", name)
        if code != 1:
            return None
        node: Any = xmlrpc.client.ServerProxy(uri)
        _, _, pid = node.getPid("/test")
    except OSError:
        return None
    return int(pid)


def ancestors(pid: int) -> list[tuple[int, str]]:
    """(pid, program name) of each ancestor of ``pid``, nearest first."""
    out = []
    while pid > 1:
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
        except OSError:
            break
        _name, rest = stat.split(" (", 1)[1].rsplit(")", 1)
        pid = int(rest.split()[1])
        out.append((pid, Path(f"/proc/{pid}/comm").read_text().strip() if pid > 1 else "init"))
    return out


def test_a_node_on_a_machine_runs_there_over_ssh(sshd: Server, tmp_path: Path) -> None:
    env = package_tree(tmp_path, extra=(REPO / "robots" / "smartcar_description",))
    path = tmp_path / "src" / "machines.launch"
    # what a ROS 1 computer's env-loader does: its setup (here: the system's python3, where
    # rospy is, before the login's pyenv shims), then the command
    loader = tmp_path / "env.sh"
    loader.write_text('#!/bin/sh\nPATH=/usr/bin:$PATH\nexport PATH\nexec "$@"\n')
    loader.chmod(0o755)
    path.write_text(LAUNCH.format(alias=HOST_ALIAS, loader=loader))
    port = free_port()
    env.update(
        MLAUNCH_SSH_CONFIG=str(sshd.client_config),
        ROS_MASTER_URI=f"http://localhost:{port}/",
        PYTHONUNBUFFERED="1",
    )
    run = Running([sys.executable, "-m", "mlaunch", str(path), "--ros1"], env=env)
    ok = False
    try:
        # registered with the run's master (not the default port) under its namespace: the
        # master and ROS_NAMESPACE reached it through ssh
        wait_for(
            lambda: (
                node_pid(port, "/away/joint_state_publisher") is not None
                and node_pid(port, "/robot_state_publisher") is not None
            ),
            timeout=60,
            what="both nodes registered",
        )
        far = node_pid(port, "/away/joint_state_publisher")
        here = node_pid(port, "/robot_state_publisher")
        assert far is not None and here is not None
        far_line = ancestors(far)
        assert "sshd" in [name for _, name in far_line], far_line  # started by the ssh server
        assert run.proc.pid not in [p for p, _ in far_line], far_line
        assert run.proc.pid in [p for p, _ in ancestors(here)]  # 'here' is this computer
        ok = True
    finally:
        run.signal(signal.SIGINT)
        run.finish(timeout=30)
        if not ok:
            print(run.text[-4000:])  # the run's output, for the failure above
    assert run.proc.returncode == 130, run.text[-3000:]  # ended by SIGINT, cleanly
    assert not os.path.exists(f"/proc/{far}")  # the remote node ended with the run
