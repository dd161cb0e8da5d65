"""Launch syntax newer than Jazzy, which Jazzy users copy from Kilted and Rolling files: ForEach
and ForLoop (Python, ``<for_each>``, ``<for>``, ``$(for-var)``, ``$(index)``) and
StringJoinSubstitution (``$(string-join)``) run under mlaunch, the same in the three formats,
and ``--check`` names each as newer than Jazzy with the release that has it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from procutil import REPO, clean_env, run_mlaunch

NEWER = REPO / "tests" / "launches" / "newer"
FORMATS = ["loop.launch.py", "loop.launch.yaml", "loop.launch.xml"]


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))


def _plan(text: str) -> list[str]:
    """The plan's logs and each process's label and argv, without file names."""
    return [
        re.sub(r"\s+\S+\.launch\.\w+:\d+$", "", line)
        for line in text.splitlines()
        if line.startswith(("log [", "echo-")) or line.startswith("  argv:")
    ]


@pytest.mark.parametrize("name", FORMATS)
def test_loops_and_string_join_run_in_each_format(name: str, env: dict[str, str]) -> None:
    done = run_mlaunch(str(NEWER / name), "--print", "num:=3", env=env)
    assert done.returncode == 0, done.stderr
    assert _plan(done.stdout) == [
        "log [INFO] 'robotA' id=1 opt=none",
        "echo-robotA-1",
        "  argv:    echo robotA",
        "log [INFO] 'robotB' id=2 opt=none",
        "echo-robotB-2",
        "  argv:    echo robotB",
        "log [INFO] i=0",
        "log [INFO] i=1",
        "log [INFO] i=2",
        "log [INFO] https://3.ros.org",
    ]


@pytest.mark.parametrize("name", FORMATS)
def test_check_names_each_as_newer_than_jazzy_with_its_release(
    name: str, env: dict[str, str]
) -> None:
    done = run_mlaunch(str(NEWER / name), "--check", env=env)
    assert done.returncode == 1, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    newer = [line for line in lines if "is newer than Jazzy" in line]
    assert newer and len(newer) == len(lines) - 1, done.stdout  # nothing else is found
    kilted = "launch 3.8 (Kilted, ros2/launch#802) has it, ros2 launch (Jazzy) fails on it"
    if name.endswith(".py"):
        assert any("launch.actions.ForEach is newer" in line and kilted in line for line in lines)
        assert any("launch.actions.ForLoop is newer" in line for line in lines)
        assert any(
            "StringJoinSubstitution is newer" in line and "3.8.1 (Kilted" in line for line in lines
        )
    else:
        assert any("the tag 'for_each' is newer" in line and kilted in line for line in lines)
        assert any("the tag 'for' is newer" in line for line in lines)
        assert any("$(for-var ...) is newer" in line for line in lines)
        assert any("$(index ...) is newer" in line for line in lines)
        assert any(
            "$(string-join ...) is newer" in line and "3.9.5 (Rolling" in line for line in lines
        )


def test_iteration_values_stay_in_their_iteration(tmp_path: Path, env: dict[str, str]) -> None:
    path = tmp_path / "leak.launch.yaml"
    path.write_text(
        "launch:\n"
        "- for_each:\n"
        '    values: "{name: a};{}"\n'
        "    children:\n"
        '    - log: {message: "in=$(for-var name unset)"}\n'
        '- log: {message: "after=$(for-var name)"}\n'
    )
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2
    assert f"{path}:6" in done.stderr and "no value for ForEachVar 'name' here" in done.stderr


@pytest.mark.parametrize(
    ("values", "error"),
    [
        ("5", "ForEach values '5' are not a YAML mapping"),
        ("{a: [}", "ForEach values '{a: [}' are not YAML"),
    ],
)
def test_bad_foreach_values_are_a_located_error(
    tmp_path: Path, env: dict[str, str], values: str, error: str
) -> None:
    path = tmp_path / "bad.launch.xml"
    path.write_text(
        f'<launch>\n<for_each values="{values}"><log message="x"/></for_each>\n</launch>\n'
    )
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2
    assert f"{path}:2" in done.stderr and error in done.stderr, done.stderr


def test_a_for_length_that_is_no_number_is_a_located_error(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "len.launch.xml"
    path.write_text(
        '<launch>\n<for len="two" name="i"><log message="$(index i)"/></for>\n</launch>\n'
    )
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2
    assert f"{path}:2" in done.stderr
    assert "ForLoop's length is 'two'; it must be a whole number" in done.stderr, done.stderr


def test_check_names_the_lifecycle_node_tag_as_newer(tmp_path: Path, env: dict[str, str]) -> None:
    """It said "Jazzy has no tag 'lifecycle_node'", as for a misspelt tag."""
    path = tmp_path / "lc.launch.xml"
    path.write_text(
        '<launch>\n<lifecycle_node pkg="p" exec="e" name="lc" namespace=""/>\n</launch>\n'
    )
    done = run_mlaunch(str(path), "--check", env=env)
    assert done.returncode == 1
    assert (
        f"{path}:2:1: the tag 'lifecycle_node' is newer than Jazzy: launch_ros after 0.29.3"
        " (Rolling, ros2/launch_ros#482) has it" in done.stdout
    ), done.stdout


@pytest.mark.parametrize("ext", ["xml", "yaml"])
def test_a_composable_lifecycle_node_says_it_is_newer_and_not_run_yet(
    tmp_path: Path, env: dict[str, str], ext: str
) -> None:
    """It was "unexpected tag <composable_lifecycle_node> (did you mean 'composable_node'?)"."""
    path = tmp_path / f"c.launch.{ext}"
    if ext == "xml":
        path.write_text(
            '<launch>\n<node_container pkg="rclcpp_components" exec="component_container"'
            ' name="c" namespace="">\n<composable_lifecycle_node pkg="p" plugin="p::N" name="n"'
            ' autostart="true"/>\n</node_container>\n</launch>\n'
        )
    else:
        path.write_text(
            "launch:\n- node_container:\n    pkg: rclcpp_components\n"
            "    exec: component_container\n    name: c\n    namespace: ''\n"
            "    composable_lifecycle_node:\n    - {pkg: p, plugin: p::N, name: n}\n"
        )
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2
    assert "composable_lifecycle_node" in done.stderr and (
        "is newer than Jazzy (launch_ros 0.29.3, Rolling, ros2/launch_ros#480) and mlaunch does"
        " not run it yet: write a composable_node" in done.stderr
    ), done.stderr
    checked = run_mlaunch(str(path), "--check", env=env)
    assert checked.returncode == 1
    assert "mlaunch does not run it yet either" in checked.stdout, checked.stdout
