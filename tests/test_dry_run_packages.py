"""A launch file away from its packages (issue 27, item 17): the error says how to point mlaunch
at them, and ``--print`` shows the plan of a workspace that is not built, with a warning for
each missing program, while a run still refuses before it starts anything."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from procutil import clean_env, mlaunch

NODES = """from launch import LaunchDescription
from launch.actions import ExecuteProcess
from launch_ros.actions import Node
def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=["echo", "first"], name="first"),
        Node(package="{package}", executable="driver"),
        Node(package="{package}", executable="planner"),
        ExecuteProcess(cmd=["no_such_program_27"]),
    ])
"""
PACKAGE_XML = """<?xml version="1.0"?>
<package format="3"><name>{name}</name><version>0.0.1</version><description>d</description>
<maintainer email="a@b.c">a</maintainer><license>MIT</license>
<export><build_type>ament_cmake</build_type></export></package>
"""


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    environ = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
    for name in ("AMENT_PREFIX_PATH", "MLAUNCH_PACKAGE_PATH", "COLCON_PREFIX_PATH"):
        environ.pop(name, None)
    return environ


def run(tmp_path: Path, env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        mlaunch(*args), capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60,
        stdin=subprocess.DEVNULL,
    )  # fmt: skip


def source_workspace(tmp_path: Path) -> Path:
    """``ws/src/pkg27``: a package checked out, never built; the launch file lives elsewhere."""
    package = tmp_path / "ws" / "src" / "pkg27"
    package.mkdir(parents=True)
    (package / "package.xml").write_text(PACKAGE_XML.format(name="pkg27"))
    launch = tmp_path / "away" / "robot.launch.py"
    launch.parent.mkdir()
    launch.write_text(NODES.format(package="pkg27"))
    return launch


def test_a_launch_file_outside_the_repository_is_told_how_to_find_its_packages(
    tmp_path: Path, env: dict[str, str]
) -> None:
    launch = tmp_path / "robot.launch.py"
    launch.write_text(NODES.format(package="mlaunch_demo"))
    done = run(tmp_path, env, str(launch))
    assert done.returncode == 2, done.stderr
    assert "searched under: (none)" not in done.stderr
    assert "--package-path DIR" in done.stderr and "MLAUNCH_PACKAGE_PATH" in done.stderr
    assert "process started" not in done.stdout


def test_print_shows_the_plan_of_a_workspace_that_is_not_built(
    tmp_path: Path, env: dict[str, str]
) -> None:
    launch = source_workspace(tmp_path)
    done = run(tmp_path, env, str(launch), "--print", "--package-path", "ws/src")
    assert done.returncode == 0, done.stderr
    assert "4 process(es) at start" in done.stdout
    warnings = [line for line in done.stdout.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 3, warnings  # one per missing program
    assert "'driver' exists once it is built" in warnings[0] and "'pkg27/driver'" in warnings[0]
    assert "'planner' exists once it is built" in warnings[1]
    assert "'no_such_program_27' not found on the PATH" in warnings[2]
    assert all("a run refuses to start" in w for w in warnings)
    assert "argv:    pkg27/driver --ros-args" in done.stdout


def test_a_run_of_it_still_refuses_before_anything_starts(
    tmp_path: Path, env: dict[str, str]
) -> None:
    launch = source_workspace(tmp_path)
    env["MLAUNCH_PACKAGE_PATH"] = str(tmp_path / "ws" / "src")
    done = run(tmp_path, env, str(launch))
    assert done.returncode == 2, done.stderr
    assert "'driver' exists once it is built and installed" in done.stderr
    assert "process started" not in done.stdout and "first" not in done.stdout
