"""A native ROS 1 run finds a node's program where roslaunch finds it: catkin's workspaces
(``CMAKE_PREFIX_PATH`` entries with a ``.catkin`` marker, then /usr), their ``lib/PKG`` and
``share/PKG`` and the source spaces a devel space's marker names, then the package's folder.
Debian's roslib (``roslib.packages.find_node``, what roslaunch calls) is the oracle."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from ros1tree import SYSTEM_PYTHON, requires_roslaunch

from mlaunch.parts.ros1_native import find_node
from mlaunch.ros1.config import Ros1Node
from mlaunch.ros1.lookup import package_finder

pytestmark = requires_roslaunch

ROSLIB = """
import json, sys
import roslib.packages, rospkg
out = {}
for pkg, kind in zip(sys.argv[1::2], sys.argv[2::2]):
    try:
        found = roslib.packages.find_node(pkg, kind, rospack=rospkg.RosPack())
    except rospkg.ResourceNotFound:
        found = None
    out[pkg + "/" + kind] = found[0] if found else None
print(json.dumps(out))
"""

PACKAGE = (
    '<package format="2"><name>{}</name><version>0.0.0</version><description>t</description>'
    "<maintainer email='t@e.st'>t</maintainer><license>BSD</license></package>"
)


def program(path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("#!/bin/sh\nexit 0\n")
    path.chmod(0o755)


def package(folder: Path, name: str) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(PACKAGE.format(name))


def workspaces(root: Path) -> dict[str, str]:
    """A catkin workspace as catkin_make leaves it (src + devel with its marker), an install
    space, a plain CMake prefix without a marker, and a package with its program in its folder."""
    src, devel, install = root / "ws" / "src", root / "ws" / "devel", root / "install"
    package(src / "built", "built")  # built in the workspace: the program is in devel/lib
    program(devel / "lib" / "built" / "talker")
    program(src / "built" / "scripts" / "talker")  # devel first: the workspace wins
    package(src / "scripted", "scripted")  # a script only in its source folder
    program(src / "scripted" / "scripts" / "listener")
    (devel / ".catkin").write_text(str(src))
    package(install / "share" / "installed", "installed")
    program(install / "lib" / "installed" / "node")
    (install / ".catkin").write_text("")
    plain = root / "plain"  # no marker: catkin ignores it
    package(plain / "share" / "unmarked", "unmarked")
    program(plain / "lib" / "unmarked" / "node")
    program(plain / "share" / "unmarked" / "bin" / "node")  # rospack's folder walk finds this
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CMAKE_"))}
    env["ROS_PACKAGE_PATH"] = os.pathsep.join([str(src), str(install / "share"), str(plain)])
    env["CMAKE_PREFIX_PATH"] = os.pathsep.join([str(devel), str(install), str(plain)])
    env["ROS_HOME"] = str(root / "ros_home")
    return env


CASES = (
    ("built", "talker"),
    ("scripted", "listener"),
    ("installed", "node"),
    ("unmarked", "node"),
    ("robot_state_publisher", "robot_state_publisher"),  # Debian's, in /usr/lib
    ("installed", "missing"),
)


def test_programs_are_found_where_roslaunch_finds_them(tmp_path: Path) -> None:
    env = workspaces(tmp_path)
    argv = [SYSTEM_PYTHON, "-c", ROSLIB, *(x for case in CASES for x in case)]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    theirs = json.loads(done.stdout)
    finder = package_finder(str(tmp_path / "none.launch"), env)
    for pkg, kind in CASES:
        node = Ros1Node(package=pkg, type=kind, name=kind, namespace="/")
        found, _ = find_node(node, finder, env)
        assert found == theirs[f"{pkg}/{kind}"], (pkg, kind)
    assert theirs["built/talker"] == str(tmp_path / "ws" / "devel" / "lib" / "built" / "talker")
    assert theirs["unmarked/node"].endswith("share/unmarked/bin/node")
    assert theirs["installed/missing"] is None


@pytest.mark.parametrize("marker", ["", "nothing-here"])
def test_a_marker_without_source_spaces_is_still_a_workspace(tmp_path: Path, marker: str) -> None:
    env = workspaces(tmp_path)
    (tmp_path / "install" / ".catkin").write_text(marker)
    finder = package_finder(str(tmp_path / "none.launch"), env)
    found, _ = find_node(
        Ros1Node(package="installed", type="node", name="n", namespace="/"), finder, env
    )
    assert found == str(tmp_path / "install" / "lib" / "installed" / "node")
