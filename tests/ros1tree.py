"""A throw-away ROS 1 package tree for the differential tests, and the real roslaunch as oracle.

``package_tree(root, cases...)`` copies case folders of tests/ros1diff (each holds ROS 1
packages) under ``root/src``, adds a ``xacro`` package whose ``xacro`` program is the PyPI
xacro (Debian packages no ROS 1 xacro), and an ament index of the same packages (the PyPI xacro
finds packages through it). ``oracle(file, args, env)`` resolves a file with roslaunch's own
Python API (``roslaunch.config.load_config_default``) under Debian's /usr/bin/python3.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

HERE = Path(__file__).resolve().parent
CASES = HERE / "ros1diff"
ORACLE = HERE / "ros1_oracle.py"
SYSTEM_PYTHON = "/usr/bin/python3"


def roslaunch_missing() -> str | None:
    """Why the real roslaunch cannot be the oracle here (None: it can)."""
    if not os.access(SYSTEM_PYTHON, os.X_OK):
        return f"{SYSTEM_PYTHON} is missing (the ROS 1 oracle runs under Debian's Python)"
    done = subprocess.run(
        [SYSTEM_PYTHON, "-c", "import roslaunch.config"], capture_output=True, check=False
    )
    if done.returncode != 0:
        return "roslaunch is not installed (apt-get install python3-roslaunch)"
    return None


requires_roslaunch = pytest.mark.skipif(
    roslaunch_missing() is not None, reason=str(roslaunch_missing())
)


def package_tree(root: Path, *cases: str, extra: tuple[Path, ...] = ()) -> dict[str, str]:
    """Build the tree (``extra``: more folders to copy in); returns the environment both
    resolvers use."""
    src = root / "src"
    for case in cases:
        shutil.copytree(CASES / case, src / case, dirs_exist_ok=True)
    for folder in extra:
        if folder.is_dir():
            shutil.copytree(folder, src / folder.name)
        else:
            src.mkdir(parents=True, exist_ok=True)
            shutil.copy(folder, src / folder.name)
    xacro = src / "xacro"
    xacro.mkdir(parents=True, exist_ok=True)
    (xacro / "package.xml").write_text(_manifest("xacro"))
    program = xacro / "xacro"
    program.write_text(f"#!{sys.executable}\nimport xacro\nxacro.main()\n")
    program.chmod(0o755)
    index = root / "ament" / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    for manifest in src.rglob("package.xml"):
        name = _name(manifest)
        (index / name).touch()
        (root / "ament" / "share" / name).symlink_to(manifest.parent)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "AMENT_"))}
    env.update(ROS_PACKAGE_PATH=str(src), AMENT_PREFIX_PATH=str(root / "ament"))
    env["ROS_HOME"] = str(root / "ros_home")
    env["HOME"] = str(root)
    return env


def _manifest(name: str) -> str:
    return (
        f'<package format="2"><name>{name}</name><version>0.0.0</version>'
        "<description>test</description><maintainer email='t@e.st'>t</maintainer>"
        "<license>BSD</license></package>\n"
    )


def _name(manifest: Path) -> str:
    text = manifest.read_text()
    return text.split("<name>", 1)[1].split("</name>", 1)[0].strip()


def oracle(path: Path, args: dict[str, str], env: dict[str, str]) -> dict[str, Any]:
    """What the real roslaunch resolves ``path`` to: nodes and typed parameters."""
    argv = [SYSTEM_PYTHON, str(ORACLE), str(path), *(f"{k}:={v}" for k, v in args.items())]
    done = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=60, check=False)
    assert done.returncode == 0, f"roslaunch refused {path}: {done.stderr[-3000:]}"
    found: dict[str, Any] = json.loads(done.stdout)
    return found
