"""Native ROS 1 runs: the seed's smartcar run by mlaunch (--ros1) and by the real roslaunch,
each with its own master, give the same parameter server (read over the master's XML-RPC
API) and the same node command lines (read from /proc)."""

from __future__ import annotations

import os
import re
import shutil
import signal
import sys
import xmlrpc.client
from pathlib import Path
from typing import Any

import pytest
from ports import free_port
from procutil import Running, wait_for
from ros1tree import SYSTEM_PYTHON, package_tree, requires_roslaunch

REPO = Path(__file__).resolve().parent.parent
SMARTCAR = "smartcar_display.launch"
NODES = ("/usr/lib/robot_state_publisher/robot_state_publisher", "/usr/lib/rosout/rosout")

pytestmark = [
    requires_roslaunch,
    pytest.mark.skipif(
        shutil.which("rosmaster") is None or not all(os.access(p, os.X_OK) for p in NODES),
        reason="Debian's rosmaster, rosout and robot_state_publisher are not installed",
    ),
]


def master(port: int) -> Any:
    return xmlrpc.client.ServerProxy(f"http://localhost:{port}/")


def registered(port: int, names: set[str]) -> bool:
    """Whether every node in ``names`` publishes something (is registered with the master)."""
    try:
        _, _, (publishers, _, _) = master(port).getSystemState("/test")
    except OSError:
        return False
    found = {node for _, nodes in publishers for node in nodes}
    return names <= found


def children_argv(root: int) -> dict[str, list[str]]:
    """Every descendant of ``root`` that is a ROS 1 node: its __name, and its argv."""
    parents: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            parents[int(entry)] = int(stat.rsplit(")", 1)[1].split()[1])
    found: dict[str, list[str]] = {}
    for pid in parents:
        ancestor = parents.get(pid)
        while ancestor and ancestor != root:
            ancestor = parents.get(ancestor)
        if ancestor != root:
            continue
        try:
            argv = Path(f"/proc/{pid}/cmdline").read_bytes().decode().split("\0")[:-1]
        except OSError:
            continue
        names = [a.split(":=", 1)[1] for a in argv if a.startswith("__name:=")]
        if names:
            found[names[0]] = argv
    return found


def observe(
    argv: list[str], env: dict[str, str], port: int, said: list[str] | None = None
) -> tuple[dict[str, Any], Any]:
    """Start a run, wait until its nodes are up, read its parameter server and command lines
    (and what it printed, into ``said``)."""
    run = Running(argv, env={**env, "ROS_MASTER_URI": f"http://localhost:{port}/"})
    try:
        wait_for(
            lambda: registered(port, {"/rosout", "/joint_state_publisher"}),
            timeout=60,
            what=f"the nodes of {argv[:2]} registered with the master: {run.text[-2000:]}",
        )
        _, _, params = master(port).getParam("/test", "/")
        return params, children_argv(run.proc.pid)
    finally:
        run.signal(signal.SIGINT)
        run.finish(timeout=30)
        if said is not None:
            said.append(run.text)


def normal(argv: list[str], run_id: str) -> list[str]:
    return [a.replace(run_id, "RUN") for a in argv]


def test_native_smartcar_matches_roslaunch(tmp_path: Path) -> None:
    seed = (REPO / "robots" / "smartcar_description", REPO / "launches" / SMARTCAR)
    env = package_tree(tmp_path, extra=seed)
    launch = str(tmp_path / "src" / SMARTCAR)
    env.update(ROS_VERSION="1", ROS_DISTRO="noetic", PYTHONUNBUFFERED="1")
    # a shell set up for ROS 1: the system's python3 first (as on a ROS 1 machine)
    env["PATH"] = os.pathsep.join(["/usr/bin", env.get("PATH", "")])
    theirs, their_nodes = observe([SYSTEM_PYTHON, "/usr/bin/roslaunch", launch], env, free_port())
    said: list[str] = []
    ours, our_nodes = observe([sys.executable, "-m", "mlaunch", launch], env, free_port(), said)
    # roslaunch also lists its own server's URI (mlaunch has no roslaunch server)
    theirs.pop("roslaunch")
    assert ours.keys() == theirs.keys()
    for key in theirs:
        if key != "run_id":
            assert ours[key] == theirs[key], key
    # The old name state_publisher fails under roslaunch. Debian's rviz, where it is installed,
    # has no display here and may be gone before either run is looked at: compared when both saw it.
    assert {"rosout", "joint_state_publisher"} <= set(their_nodes) & set(our_nodes)
    assert "robot_state_publisher" not in their_nodes
    for name in set(their_nodes) & set(our_nodes):
        expected = normal(their_nodes[name], theirs["run_id"])
        assert normal(our_nodes[name], ours["run_id"]) == expected, name
    assert set(their_nodes) - set(our_nodes) <= {"rviz"}
    # the old name runs its replacement, with roslaunch's arguments for it
    rsp = normal(our_nodes["robot_state_publisher"], ours["run_id"])
    log_dir = re.sub(r"/[^/]+$", "", normal(their_nodes["rosout"], theirs["run_id"])[-1])
    assert rsp == [
        NODES[0],
        "__name:=robot_state_publisher",
        f"{log_dir}/robot_state_publisher-4.log",
    ]
    # Each process is labelled as roslaunch names it, the name its __log:= file carries (the
    # labels were mlaunch's count, which also counts the master and the parameter loader).
    for name in ("rosout", "joint_state_publisher", "robot_state_publisher"):
        label = our_nodes[name][-1].rsplit("/", 1)[1].removesuffix(".log")
        assert f"[{label}]: process started" in said[0], (label, said[0][-3000:])
