"""Machines in launch files: Machine, PushMachine and machine= resolve the same in py, yaml, xml.

Pure resolve tests (no ssh): which process gets which machine, scoping, defaults, local
machines, and the located errors.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from mlaunch import readers
from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.steps import Plan
from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve

EXAMPLES_PREFIX = Path(__file__).resolve().parent.parent / "launches" / "examples" / "prefix"

PY = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess, GroupAction
from mlaunch.actions import Machine, PushMachine

def generate_launch_description():
    return LaunchDescription([
        Machine(name="robot", address="robot-alias", user="ros", ssh_port=2200,
                env_loader="/opt/env.sh", timeout=3),
        Machine(name="gpu", address="gpu-alias", default=True),
        ExecuteProcess(cmd=["a"], name="a"),
        ExecuteProcess(cmd=["b"], name="b", machine="robot"),
        GroupAction([PushMachine("robot"), ExecuteProcess(cmd=["c"], name="c")]),
        ExecuteProcess(cmd=["d"], name="d"),
    ])
"""

XML = """<launch>
  <machine name="robot" address="robot-alias" user="ros" ssh-port="2200"
           env-loader="/opt/env.sh" timeout="3"/>
  <machine name="gpu" address="gpu-alias" default="true"/>
  <executable cmd="a" name="a"/>
  <executable cmd="b" name="b" machine="robot"/>
  <group>
    <push-machine name="robot"/>
    <executable cmd="c" name="c"/>
  </group>
  <executable cmd="d" name="d"/>
</launch>
"""

YAML = """launch:
- machine: {name: robot, address: robot-alias, user: ros, ssh-port: 2200,
            env-loader: /opt/env.sh, timeout: 3}
- machine: {name: gpu, address: gpu-alias, default: true}
- executable: {cmd: a, name: a}
- executable: {cmd: b, name: b, machine: robot}
- group:
    children:
    - push-machine: {name: robot}
    - executable: {cmd: c, name: c}
- executable: {cmd: d, name: d}
"""


def resolve_text(tmp_path: Path, suffix: str, text: str) -> Plan:
    path = tmp_path / f"m.launch.{suffix}"
    path.write_text(text)
    return resolve(
        readers.load(str(path)),
        path=str(path),
        arguments={},
        environ={"PATH": os.environ["PATH"]},
        options=ResolveOptions(temp_dir=str(tmp_path)),
        labels=LabelCounter(),
    )


def placement(plan: Plan) -> dict[str, str | None]:
    return {
        spec.base_name: None if spec.machine is None else spec.machine.name
        for spec in plan.processes()
    }


@pytest.mark.parametrize(("suffix", "text"), [("py", PY), ("xml", XML), ("yaml", YAML)])
def test_the_three_spellings_place_processes_alike(tmp_path: Path, suffix: str, text: str) -> None:
    plan = resolve_text(tmp_path, suffix, text)
    # gpu is the default from its declaration on; the group's push stays in the group.
    assert placement(plan) == {"a": "gpu", "b": "robot", "c": "robot", "d": "gpu"}
    robot = next(s.machine for s in plan.processes() if s.base_name == "b")
    assert robot is not None
    assert (robot.address, robot.user, robot.ssh_port) == ("robot-alias", "ros", 2200)
    assert (robot.env_loader, robot.timeout, robot.local) == ("/opt/env.sh", 3.0, False)
    # A remote program is found on that computer: not looked up (or replaced) here.
    assert next(s.argv for s in plan.processes() if s.base_name == "b") == ("b",)


def test_a_local_address_runs_here(tmp_path: Path) -> None:
    text = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess
from mlaunch.actions import Machine

def generate_launch_description():
    return LaunchDescription([
        Machine(name="here", address="127.0.0.1"),
        ExecuteProcess(cmd=["true"], machine="here"),
    ])
"""
    spec = resolve_text(tmp_path, "py", text).processes()[0]
    assert spec.machine is not None and spec.machine.local
    # Found here, as any local program: a missing one is this computer's error.
    with pytest.raises(MlaunchError, match="'no-such-program' not found on the PATH"):
        resolve_text(tmp_path, "py", text.replace('"true"', '"no-such-program"'))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('machine="robot")', 'machine="robt")'), r"machine 'robt' is not declared \(did you mean"),
        (("ssh_port=2200", "ssh_port=70000"), r"ssh_port of machine 'robot' is 70000"),
        (("timeout=3", "timeout=0"), r"timeout of machine 'robot' is 0"),
        (('"robot-alias"', '"-oProxyCommand=x"'), r"address of machine 'robot' is '-oProxy"),
        (('name="gpu", address="gpu-alias"', 'name="robot", address="x"'), r"declared again"),
    ],
)
def test_bad_machines_are_located_errors(
    tmp_path: Path, change: tuple[str, str], message: str
) -> None:
    with pytest.raises(MlaunchError, match=message) as info:
        resolve_text(tmp_path, "py", PY.replace(*change))
    assert "m.launch.py:" in str(info.value)


def test_xml_machine_attribute_of_an_undeclared_machine_names_the_line(tmp_path: Path) -> None:
    text = '<launch>\n  <executable cmd="a" machine="nowhere"/>\n</launch>\n'
    with pytest.raises(MlaunchError, match=r"m\.launch\.xml:2.*'nowhere' is not declared"):
        resolve_text(tmp_path, "xml", text)


ROS1 = """<launch>
  <arg name="host" default="robot-alias"/>
  <machine name="robot" address="$(arg host)" user="ros" ssh-port="2200"
           env-loader="/opt/env.sh" timeout="3" password="secret"/>
  <machine name="gpu" address="gpu-alias" default="true"/>
  <node pkg="mlaunch_demo" type="talker" name="a"/>
  <node pkg="mlaunch_demo" type="talker" name="b" machine="robot"/>
</launch>
"""


@pytest.mark.parametrize("fmt", ["ros1", "py", "yaml", "xml"])
def test_ros1_machines_run_and_convert_alike(tmp_path: Path, fmt: str) -> None:
    from mlaunch.commands.convert import convert

    source = tmp_path / "m.launch"
    source.write_text(ROS1)
    path = source
    if fmt != "ros1":
        path = tmp_path / f"converted.launch.{fmt}"
        path.write_text(convert(str(source), fmt, str(path)))
    plan = resolve(
        readers.load(str(path)),
        path=str(path),
        arguments={},
        environ={"PATH": os.environ["PATH"], "AMENT_PREFIX_PATH": str(EXAMPLES_PREFIX)},
        options=ResolveOptions(temp_dir=str(tmp_path)),
        labels=LabelCounter(),
    )
    machines = {
        (s.node.name if s.node else s.label): s.machine and s.machine.describe()
        for s in plan.processes()
    }
    assert machines == {
        "a": "gpu (ssh gpu-alias)",
        "b": "robot (ssh ros@robot-alias:2200, env-loader /opt/env.sh)",
    }
    if fmt == "ros1":
        assert any("<machine password> is ignored" in w for w in plan.warnings)


def test_ros1_node_on_an_undeclared_machine_is_a_located_error(tmp_path: Path) -> None:
    path = tmp_path / "m.launch"
    path.write_text(
        '<launch>\n  <node pkg="mlaunch_demo" type="talker" name="t" machine="far"/>\n</launch>\n'
    )
    with pytest.raises(MlaunchError, match=r"m\.launch:2.*machine 'far' is not declared"):
        resolve(
            readers.load(str(path)),
            path=str(path),
            arguments={},
            environ={"PATH": os.environ["PATH"], "AMENT_PREFIX_PATH": str(EXAMPLES_PREFIX)},
            options=ResolveOptions(temp_dir=str(tmp_path)),
            labels=LabelCounter(),
        )


def test_a_launch_without_machines_never_imports_them(tmp_path: Path) -> None:
    import subprocess
    import sys

    path = tmp_path / "plain.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([ExecuteProcess(cmd=['true'])])\n"
    )
    done = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "mlaunch", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "| mlaunch.engine.supervisor" in done.stderr  # the run really happened
    assert "mlaunch.machines" not in done.stderr
