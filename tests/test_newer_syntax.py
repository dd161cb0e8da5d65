"""Launch syntax newer than Jazzy, which Jazzy users copy from Kilted and Rolling files: ForEach
and ForLoop (Python, ``<for_each>``, ``<for>``, ``$(for-var)``, ``$(index)``) and
StringJoinSubstitution (``$(string-join)``) and ComposableLifecycleNode
(``<composable_lifecycle_node>``) run under mlaunch, the same in the three formats, and
``--check`` names each as newer than Jazzy with the release that has it."""

from __future__ import annotations

import json
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


LIFECYCLE_COMPONENT = ["lifecycle_component.launch." + ext for ext in ("xml", "yaml", "py")]


def _loads(name: str, *args: str) -> list[object]:
    """The plan's component loads as --print --format json gives them, without their file."""
    done = run_mlaunch(str(NEWER / name), "--print", "--format", "json", *args, env=clean_env())
    assert done.returncode == 0, done.stderr
    steps = json.loads(done.stdout)["steps"]
    loads = [s for s in steps if s["kind"] == "load_components"]
    for load in loads:
        load.pop("origin", None)
    return loads


def test_a_composable_lifecycle_node_is_the_same_plan_in_xml_yaml_and_python() -> None:
    """It was "<composable_lifecycle_node> is newer than Jazzy ... and mlaunch does not run it
    yet" (exit 2): now a component to load, after the composable_node ones, marked to be
    brought up (autostart), the same in the three formats; autostart:=false drops the mark."""
    xml, yaml, python = (_loads(name) for name in LIFECYCLE_COMPONENT)
    assert xml == yaml == python
    (load,) = xml
    assert isinstance(load, dict) and load["container"] == "/c"
    nodes = load["nodes"]
    assert [n["full_name"] for n in nodes] == ["/plain", "/robot/n"]
    assert "autostart" not in nodes[0] and nodes[1]["autostart"] is True
    for name in LIFECYCLE_COMPONENT:
        (off,) = _loads(name, "up:=false")
        assert isinstance(off, dict) and all("autostart" not in n for n in off["nodes"]), name
    text = run_mlaunch(str(NEWER / LIFECYCLE_COMPONENT[0]), "--print", env=clean_env()).stdout
    assert "component /robot/n   (loaded into /c)" in text
    assert "  lifecycle: autostart (configured and activated once loaded)" in text


@pytest.mark.parametrize("name", LIFECYCLE_COMPONENT)
def test_check_names_the_composable_lifecycle_node_as_newer_and_run(
    name: str, env: dict[str, str]
) -> None:
    """--check said "mlaunch does not run it yet either"."""
    done = run_mlaunch(str(NEWER / name), "--check", env=env)
    assert done.returncode == 1
    what = {
        "xml": "<composable_lifecycle_node>",
        "yaml": "'composable_lifecycle_node'",
        "py": "launch_ros.descriptions.ComposableLifecycleNode",
    }[name.rsplit(".", 1)[1]]
    assert (
        f"{what} is newer than Jazzy: launch_ros 0.29.3 (Rolling, ros2/launch_ros#480) has it,"
        " ros2 launch (Jazzy) fails on it; mlaunch runs it" in done.stdout
    ), done.stdout


def test_a_bad_autostart_of_a_composable_lifecycle_node_is_a_located_error(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "c.launch.xml"
    path.write_text(
        '<launch>\n<node_container pkg="rclcpp_components" exec="component_container"'
        ' name="c" namespace="">\n<composable_lifecycle_node pkg="p" plugin="p::N" name="n"'
        ' autostart="maybe"/>\n</node_container>\n</launch>\n'
    )
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2
    assert f"{path}:3" in done.stderr and "maybe" in done.stderr, done.stderr
