"""Malformed launch files while loading and resolving: each is one located line and exit 2.

Include cycles, nesting past the limit, a launch file that calls sys.exit(), bytes that are not
UTF-8, and many undeclared arguments against many declared ones. Each case runs the real
``python -m mlaunch FILE --print`` (nothing is spawned) and checks the exit status and that
stderr is one line naming the file and line.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

from mlaunch.frontends.limits import DEPTH_LIMIT
from mlaunch.frontends.suggest import LISTED, Suggester
from mlaunch.resolve.resolver import undeclared_argument_warnings

PY = sys.executable


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))


def fails(path: Path, env: dict[str, str], *args: str) -> str:
    """Run ``mlaunch path --print``; it must exit 2 with one line on stderr, returned."""
    # A deadline, not a speed check: the deepest files cost seconds of CPU, and at load 24 two
    # runs passed 60 s.
    done = run_mlaunch(str(path), "--print", *args, env=env, timeout=240)
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("mlaunch: error: "), lines[0]
    assert "RecursionError" not in lines[0] and "internal error" not in lines[0]
    return lines[0]


def prints(path: Path, env: dict[str, str]) -> str:
    done = run_mlaunch(str(path), "--print", env=env, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


# --- include cycles --------------------------------------------------------------------------

XML_INCLUDE = '<launch>\n  <include file="$(dirname)/{other}"/>\n</launch>\n'
YAML_INCLUDE = 'launch:\n- include:\n    file: "$(dirname)/{other}"\n'
ROS1_INCLUDE = (
    '<launch>\n  <group>\n    <include file="$(dirname)/{other}"/>\n  </group>\n</launch>\n'
)
PY_INCLUDE = """import os
from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource

def generate_launch_description():
    here = os.path.dirname(__file__)
    return LaunchDescription([
        IncludeLaunchDescription(PythonLaunchDescriptionSource(os.path.join(here, "{other}"))),
    ])
"""
CYCLES = {
    "xml": (".launch.xml", XML_INCLUDE, 2),
    "yaml": (".launch.yaml", YAML_INCLUDE, 2),
    "ros1": (".launch", ROS1_INCLUDE, 3),
    "python": (".launch.py", PY_INCLUDE, 9),
}


@pytest.mark.parametrize("fmt", sorted(CYCLES))
def test_an_include_cycle_names_the_chain_of_files_and_lines(
    tmp_path: Path, env: dict[str, str], fmt: str
) -> None:
    suffix, template, line = CYCLES[fmt]
    a, b = f"a{suffix}", f"b{suffix}"
    (tmp_path / a).write_text(template.format(other=b))
    (tmp_path / b).write_text(template.format(other=a))
    error = fails(tmp_path / a, env)
    assert "include cycle: " in error
    assert f"{b} (included at {a}:{line}) -> {a} (included at {b}:{line})" in error
    assert f"{b} again (included at {a}:{line})" in error
    assert f"{tmp_path / a}:{line}:" in error


def test_a_file_including_itself_with_an_argument_that_ends_it_still_runs(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "rec.launch.xml"
    path.write_text(
        """<launch>
  <arg name="n" default="x"/>
  <executable cmd="echo $(var n)" name="e"/>
  <include file="$(dirname)/rec.launch.xml" unless="$(eval &quot;'$(var n)' == 'xxx'&quot;)">
    <arg name="n" value="$(var n)x"/>
  </include>
</launch>
"""
    )
    out = prints(path, env)
    assert [line.split()[-1] for line in out.splitlines() if "argv:" in line] == [
        "x",
        "xx",
        "xxx",
    ]


@pytest.mark.timeout(300)  # fails()'s deadline
def test_a_cycle_that_changes_an_argument_each_time_stops_at_the_depth_limit(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "grow.launch.xml"
    path.write_text(
        '<launch>\n  <arg name="n" default=""/>\n'
        '  <include file="$(dirname)/grow.launch.xml">\n'
        '    <arg name="n" value="$(var n)x"/>\n  </include>\n</launch>\n'
    )
    error = fails(path, env)
    assert f"nest deeper than {DEPTH_LIMIT} levels, mlaunch's limit (" in error
    assert "includes deep, the innermost of grow.launch.xml at grow.launch.xml:3)" in error
    assert f"{path}:" in error


# --- nesting ---------------------------------------------------------------------------------


def nested_xml(depth: int) -> str:
    body = '<executable cmd="true" name="t"/>'
    for _ in range(depth):
        body = f"<group>{body}</group>"
    return f"<launch>\n{body}\n</launch>\n"


def nested_yaml(depth: int) -> str:
    body = '{executable: {cmd: "true", name: t}}'
    for _ in range(depth):
        body = "{group: {children: [" + body + "]}}"
    return f"launch:\n- {body}\n"


def nested_ros1(depth: int) -> str:
    body = '<env name="A" value="1"/>'
    for _ in range(depth):
        body = f"<group>{body}</group>"
    return f"<launch>\n{body}\n</launch>\n"


def nested_python(depth: int) -> str:
    return f"""from launch import LaunchDescription
from launch.actions import ExecuteProcess, GroupAction

def generate_launch_description():
    action = ExecuteProcess(cmd=["true"], name="t")
    for _ in range({depth}):
        action = GroupAction([action])
    return LaunchDescription([action])
"""


# (suffix, file maker, mlaunch's words or None, line). YAML: None, as libyaml stops deep flow
# nesting itself in some versions (PyYAML 6.0.4: "exceeded maximum nesting depth") and mlaunch's
# own check stops it in others; either way it must be one located line with exit 2.
NESTED = {
    "xml": (".launch.xml", nested_xml, "XML elements nest deeper", 2),
    "yaml": (".launch.yaml", nested_yaml, None, 2),
    "ros1": (".launch", nested_ros1, "XML elements nest deeper", 2),
    "python": (".launch.py", nested_python, "launch actions (groups, includes) nest deeper", 7),
}


@pytest.mark.parametrize("fmt", sorted(NESTED))
def test_groups_nest_deeper_than_python_allows_by_default(
    tmp_path: Path, env: dict[str, str], fmt: str
) -> None:
    # 300 levels: a RecursionError before (Python's limit); ros2 launch stops at ~190 in XML.
    suffix, make, _, _ = NESTED[fmt]
    path = tmp_path / f"deep{suffix}"
    path.write_text(make(300))
    done = run_mlaunch(str(path), "--print", env=env, timeout=60)
    assert done.returncode == 0, done.stderr


@pytest.mark.timeout(300)  # fails()'s deadline
@pytest.mark.parametrize("fmt", sorted(NESTED))
def test_nesting_past_the_limit_is_a_located_error(
    tmp_path: Path, env: dict[str, str], fmt: str
) -> None:
    suffix, make, what, line = NESTED[fmt]
    path = tmp_path / f"deeper{suffix}"
    # 20,000 YAML levels crashed libyaml's composer (a segfault) before the check.
    path.write_text(make(DEPTH_LIMIT + 10 if fmt == "python" else 20_000))
    error = fails(path, env)  # exit 2, one line, no RecursionError, no internal error
    assert what is None or what in error
    assert f"{path}:{line}:" in error or error.startswith(f"mlaunch: error: {path}:{line} ")


# --- sys.exit() in a launch file -------------------------------------------------------------

EXITS = {
    "sys.exit(3) in generate": ("import sys\n", "    sys.exit(3)\n", "sys.exit(3)", 5),
    "SystemExit(0) at import": ("raise SystemExit(0)\n", "    return None\n", "sys.exit(0)", 2),
    "sys.exit() in an OpaqueFunction": (
        "import sys\nfrom launch.actions import OpaqueFunction\n",
        "    return LaunchDescription([OpaqueFunction(function=lambda context: sys.exit(4))])\n",
        "sys.exit(4)",
        6,
    ),
}


@pytest.mark.parametrize("case", sorted(EXITS))
def test_sys_exit_in_a_launch_file_is_a_located_error(
    tmp_path: Path, env: dict[str, str], case: str
) -> None:
    head, body, called, line = EXITS[case]
    path = tmp_path / "exits.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n" + head + "\n"
        "def generate_launch_description():\n" + body
    )
    error = fails(path, env)
    assert f"the launch file called {called}" in error
    assert f"{path}:{line}:" in error


# --- bytes that are not UTF-8 ----------------------------------------------------------------

LATIN1 = {
    "xml": (".launch.xml", b'<launch>\n  <executable cmd="echo caf\xe9" name="t"/>\n</launch>\n'),
    "yaml": (".launch.yaml", b'launch:\n- executable: {cmd: "echo caf\xe9", name: t}\n'),
    "ros1": (".launch", b'<launch>\n  <env name="A" value="caf\xe9"/>\n</launch>\n'),
    "python": (".launch.py", b'from launch import LaunchDescription\nX = "caf\xe9"\n'),
}


@pytest.mark.parametrize("fmt", sorted(LATIN1))
def test_a_file_that_is_not_utf8_is_one_located_line(
    tmp_path: Path, env: dict[str, str], fmt: str
) -> None:
    suffix, data = LATIN1[fmt]
    path = tmp_path / f"latin{suffix}"
    path.write_bytes(data)
    error = fails(path, env)
    column = data.split(b"\n")[1].index(b"\xe9") + 1
    assert f"{path}:2:{column}: the file is not UTF-8 text: byte 0xE9" in error


def test_a_rosparam_file_that_is_not_utf8_names_both_files(
    tmp_path: Path, env: dict[str, str]
) -> None:
    (tmp_path / "p.yaml").write_bytes(b"a: 1\nb: caf\xe9\n")
    path = tmp_path / "r.launch"
    path.write_text('<launch>\n  <rosparam file="$(dirname)/p.yaml"/>\n</launch>\n')
    error = fails(path, env)
    assert f"{path}:2:" in error
    assert f"rosparam file {tmp_path / 'p.yaml'}:2:7: the file is not UTF-8 text" in error


def test_a_python_file_that_declares_its_encoding_runs(tmp_path: Path, env: dict[str, str]) -> None:
    path = tmp_path / "coded.launch.py"
    path.write_bytes(
        b"# -*- coding: latin-1 -*-\nfrom launch import LaunchDescription\n"
        b"from launch.actions import ExecuteProcess\n\ndef generate_launch_description():\n"
        b"    return LaunchDescription([ExecuteProcess(cmd=['echo', 'caf\xe9'], name='t')])\n"
    )
    assert "argv:    echo 'café'" in prints(path, env)


def test_a_yaml_control_character_is_one_located_line(tmp_path: Path, env: dict[str, str]) -> None:
    path = tmp_path / "ctl.launch.yaml"
    path.write_bytes(b'launch:\n- executable: {cmd: "echo \x07", name: t}\n')
    error = fails(path, env)
    assert f"{path}:2:" in error and "#x0007 is not allowed in YAML" in error


# --- "did you mean" over many declared arguments ---------------------------------------------


def test_did_you_mean_stops_comparing_past_its_budget() -> None:
    suggest = Suggester([f"arg_{i}" for i in range(100)], budget=250)
    assert suggest.hint("arg_1x") == " (did you mean 'arg_1'?)"
    assert suggest.hint("arg_2x") == " (did you mean 'arg_2'?)"
    # 200 of 250 comparisons spent: the third name gets the (capped) listing, not a search.
    third = suggest.hint("arg_3x")
    assert "did you mean" not in third
    assert third.startswith("; declared: arg_0, arg_1, arg_10,")
    assert third.endswith(f" and {100 - LISTED} more (--show-args lists them)")
    assert third.count(",") == LISTED - 1


def test_undeclared_arguments_against_many_declared_give_short_warnings() -> None:
    declared = {f"arg_{i}": None for i in range(51_000)}
    given = {f"zz_{i}": "v" for i in range(2_000)}
    warnings = undeclared_argument_warnings(given, declared)  # type: ignore[arg-type]
    assert len(warnings) == 2_000
    assert all(len(w) < 400 for w in warnings)
    assert warnings[0].endswith("and 50980 more (--show-args lists them)")


def test_a_close_name_is_still_suggested(tmp_path: Path, env: dict[str, str]) -> None:
    path = tmp_path / "args.launch.xml"
    path.write_text('<launch>\n  <arg name="speed" default="1"/>\n</launch>\n')
    done = subprocess.run(
        [PY, "-m", "mlaunch", str(path), "--print", "sped:=2"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert "argument 'sped' is not declared by the launch file (did you mean 'speed'?)" in (
        done.stdout + done.stderr
    )
