"""The real thing: argv resolved by mlaunch, run by rclpy, checked from inside the node.

A fake ament prefix holds ``lib/probe_pkg/introspect``, a wrapper that runs
``tests/nodes/introspect.py`` with this interpreter; the node prints one JSON line with its
name, namespace, parameters (with rclpy's types) and resolved topic names. The launch
description uses pushed namespaces, globals, dict params, params files, ``-p`` rules and
remaps, so what rcl makes of mlaunch's command line is checked end to end.
"""

from __future__ import annotations

import json
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import xacro
from conftest import requires_rclpy
from procutil import Running

from mlaunch.launch.actions import GroupAction, LaunchDescription
from mlaunch.launch.substitutions import Command, LaunchConfiguration
from mlaunch.launch_ros.actions import (
    Node,
    PushRosNamespace,
    SetParameter,
    SetParametersFromFile,
    SetRemap,
    with_use_sim_time,
)
from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterValue
from mlaunch.plan.steps import ProcessSpec
from mlaunch.resolve.resolver import ResolveOptions, resolve
from mlaunch.ros import packages

pytestmark = [requires_rclpy, pytest.mark.timeout(60)]

INTROSPECT = Path(__file__).resolve().parent / "nodes" / "introspect.py"
JTBOT = Path(__file__).resolve().parent.parent / "robots/jtbot_description/urdf/jtbot.urdf.xacro"


@pytest.fixture(autouse=True)
def _fresh_packages() -> Iterator[None]:
    packages.forget_scans()
    yield
    packages.forget_scans()


def fake_prefix(root: Path) -> Path:
    index = root / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "probe_pkg").write_text("")
    (root / "share" / "probe_pkg").mkdir(parents=True)
    wrapper = root / "lib" / "probe_pkg" / "introspect"
    wrapper.parent.mkdir(parents=True)
    wrapper.write_text(f'#!/bin/sh\nexec "{sys.executable}" "{INTROSPECT}" "$@"\n')
    wrapper.chmod(0o755)
    return root


def description(tmp_path: Path) -> LaunchDescription:
    global_file = tmp_path / "global.yaml"
    global_file.write_text("/**:\n  ros__parameters:\n    from_global_file: g\n")
    node_file = tmp_path / "node.yaml"
    node_file.write_text(
        "/fleet/robot1/arm/probe:\n  ros__parameters:\n    from_node_file: 7\n"
        "/**:\n  ros__parameters:\n    int_p: 1\n"  # the dict before it wins: FQN beats /**
    )
    lc = LaunchConfiguration
    probe = Node(
        package="probe_pkg",
        executable="introspect",
        name="probe",
        namespace="arm",
        arguments=["--extra"],
        ros_arguments=["--log-level", "warn"],
        parameters=[
            {
                "int_p": 42,
                "float_p": lc("f"),
                "str_p": "true",
                "bool_p": lc("b"),
                "nested": {"deep": {"x": "y"}},  # plain `y` would be a bool to rcl
                "sci_text": "1e3",  # and these numbers
                "inf_text": "inf",
                "ints": [1, 2, 3],
                "floats": [1, 2.5],
                "strs": ["a", "b"],
                "bools": [True, False],
                "desc": ParameterValue(lc("f"), value_type=str),
                "robot_description": ParameterValue(
                    Command(["xacro ", str(JTBOT)]), value_type=str
                ),
            },
            str(node_file),
            Parameter("p_rule", 5),
            Parameter("p_list", [1, 2]),
            Parameter("p_text", lc("f"), value_type=str),
        ],
        remappings=[("chatter", "talk"), ("~/private", "secret")],
    )
    anonymous = Node(package="probe_pkg", executable="introspect", parameters=[{"only_mine": "x"}])
    body = LaunchDescription(
        [
            SetParameter("global_flag", True),
            SetParameter("global_rate", 2.5),
            SetParameter("global_list", [1, 2.5]),  # -p global_list:=[1.0, 2.5]
            SetParameter("global_names", ["a b", "y"]),  # -p global_names:=[a b, 'y']
            SetParametersFromFile(str(global_file)),
            SetRemap("/absolute", "/remapped_abs"),
            GroupAction(
                [
                    PushRosNamespace("fleet"),
                    GroupAction([PushRosNamespace("robot1"), probe]),
                    anonymous,
                ]
            ),
        ]
    )
    return with_use_sim_time(body, True)  # as mlaunch --use-sim-time runs it


def start(spec: ProcessSpec) -> Running:
    return Running(spec.argv, env=spec.env)


def report(proc: Running) -> dict[str, Any]:
    match = proc.wait_for(r"^\{.*\}$", timeout=30)
    return json.loads(match.group(0))


def values(data: dict[str, Any]) -> dict[str, tuple[str, Any]]:
    return {k: (v["type"], v["value"]) for k, v in data["parameters"].items()}


def test_nodes_see_the_command_line_launch_ros_would_give(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    environ = {**ros_env, "AMENT_PREFIX_PATH": str(fake_prefix(tmp_path / "install"))}
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    plan = resolve(
        description(tmp_path),
        path=None,
        arguments={"f": "1.5", "b": "true"},
        environ=environ,
        options=ResolveOptions(temp_dir=str(run_dir)),
    )
    probe_spec, anonymous_spec = plan.processes()
    assert probe_spec.label == "introspect-1" and anonymous_spec.label == "introspect-2"
    procs = [start(probe_spec), start(anonymous_spec)]
    try:
        probe, anonymous = (report(p) for p in procs)
    finally:
        for proc in procs:
            proc.signal(signal.SIGINT)
        for proc in procs:
            try:
                proc.finish(timeout=10)
            finally:
                proc.kill()

    urdf = xacro.process_file(str(JTBOT)).toprettyxml(indent="  ")  # what the program prints
    assert urdf.count("\n") > 100
    assert (probe["name"], probe["namespace"]) == ("probe", "/fleet/robot1/arm")
    assert probe["fqn"] == "/fleet/robot1/arm/probe"
    assert probe["argv"] == ["--extra"]
    assert values(probe) == {
        "use_sim_time": ("bool", True),
        "global_flag": ("bool", True),
        "global_rate": ("double", 2.5),
        "global_list": ("double_array", [1.0, 2.5]),
        "global_names": ("string_array", ["a b", "y"]),
        "from_global_file": ("string", "g"),
        "int_p": ("integer", 42),
        "float_p": ("double", 1.5),
        "str_p": ("string", "true"),
        "bool_p": ("bool", True),
        "nested.deep.x": ("string", "y"),
        "sci_text": ("string", "1e3"),
        "inf_text": ("string", "inf"),
        "ints": ("integer_array", [1, 2, 3]),
        "floats": ("double_array", [1.0, 2.5]),
        "strs": ("string_array", ["a", "b"]),
        "bools": ("bool_array", [True, False]),
        "desc": ("string", "1.5"),
        "robot_description": ("string", urdf),
        "from_node_file": ("integer", 7),
        "p_rule": ("integer", 5),
        "p_list": ("integer_array", [1, 2]),
        "p_text": ("string", "1.5"),
        "start_type_description_service": values(probe)["start_type_description_service"],
    }
    assert probe["resolved"] == {
        "chatter": "/fleet/robot1/arm/talk",
        "~/private": "/fleet/robot1/arm/secret",
        "/absolute": "/remapped_abs",
    }

    # No name given: the node keeps its own, under the pushed namespace; /** params reach it.
    assert (anonymous["name"], anonymous["namespace"]) == ("introspect", "/fleet")
    assert values(anonymous)["only_mine"] == ("string", "x")
    assert values(anonymous)["global_rate"] == ("double", 2.5)
    assert anonymous["resolved"]["chatter"] == "/fleet/chatter"
    assert anonymous["resolved"]["/absolute"] == "/remapped_abs"
