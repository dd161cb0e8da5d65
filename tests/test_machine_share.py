"""``mlaunch FILE --machine NAME``: one machine's share of a launch, run on that machine.

Resolve tests (no ssh): which processes a share starts, with what argv, the steps it leaves to
the other shares, the handlers that wait for another share's process, ROS 1's ``<machine>``
rules; then one run of a share, with processes that say they ran.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

from mlaunch import readers
from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.steps import Elsewhere, Plan
from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve
from mlaunch.resolve.shares import check_share

EXAMPLES_PREFIX = Path(__file__).resolve().parent.parent / "launches" / "examples" / "prefix"

PY = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from mlaunch.actions import Machine

far = ExecuteProcess(cmd=["echo", "c"], name="c", machine="gpu")

def generate_launch_description():
    return LaunchDescription([
        Machine(name="robot", address="robot-alias", env_loader="/opt/env.sh"),
        Machine(name="gpu", address="gpu-alias"),
        ExecuteProcess(cmd=["echo", "a"], name="a"),
        ExecuteProcess(cmd=["echo", "b", "x y"], name="b", machine="robot"),
        far,
        ExecuteProcess(cmd=["echo $HOME"], shell=True, name="d", machine="robot"),
        RegisterEventHandler(OnProcessExit(target_action=far, on_exit=[LogInfo(msg="c ended")])),
    ])
"""


def resolve_share(tmp_path: Path, text: str, share: str | None, suffix: str = "py") -> Plan:
    path = tmp_path / f"m.launch.{suffix}"
    path.write_text(text)
    labels = LabelCounter()
    plan = resolve(
        readers.load(str(path)),
        path=str(path),
        arguments={},
        environ={"PATH": os.environ["PATH"], "AMENT_PREFIX_PATH": str(EXAMPLES_PREFIX)},
        options=ResolveOptions(temp_dir=str(tmp_path), machine=share),
        labels=labels,
    )
    if share is not None:
        check_share(plan, labels.run_state, share)
    return plan


def elsewhere(plan: Plan) -> dict[str, str]:
    return {s.spec.label: s.share for s in plan.steps if isinstance(s, Elsewhere) and s.spec}


def test_each_share_starts_its_own_processes_here_and_leaves_the_others(tmp_path: Path) -> None:
    whole = resolve_share(tmp_path, PY, None)
    assert [s.label for s in whole.processes()] == ["a-1", "b-2", "c-3", "d-4"]

    robot = resolve_share(tmp_path, PY, "robot")
    b, d = robot.processes()
    # The labels are the whole launch's; the machine's processes run here, without ssh,
    # through its env-loader as its agent runs them there (a shell command behind it).
    assert (b.label, d.label) == ("b-2", "d-4")
    assert b.machine is not None and b.machine.local and b.machine.name == "robot"
    assert b.argv[0] == "/opt/env.sh" and os.path.basename(b.argv[1]) == "echo"
    assert b.argv[2:] == ("b", "x y")
    assert d.argv == ("/opt/env.sh", "/bin/sh", "-c", "echo $HOME") and not d.shell
    assert elsewhere(robot) == {"a-1": "local", "c-3": "gpu"}

    local = resolve_share(tmp_path, PY, "local")
    assert [(s.label, s.machine) for s in local.processes()] == [("a-1", None)]
    assert elsewhere(local) == {"b-2": "robot", "c-3": "gpu", "d-4": "robot"}


def test_another_shares_programs_are_not_looked_for_here(tmp_path: Path) -> None:
    text = PY.replace('["echo", "b", "x y"]', '["no-such-program-here"]')
    with pytest.raises(MlaunchError, match="'no-such-program-here' not found"):
        resolve_share(tmp_path, text, "robot")  # its share: found here, as on that computer
    plan = resolve_share(tmp_path, text, "local")  # another share's: that computer's program
    assert elsewhere(plan)["b-2"] == "robot"


def test_a_handler_waiting_for_another_shares_process_is_said(tmp_path: Path) -> None:
    local = resolve_share(tmp_path, PY, "local")
    said = [w for w in local.warnings if "the handler for when c-3 exits" in w]
    assert len(said) == 1, local.warnings
    assert "m.launch.py:17" in said[0] and "never fires in this run (--machine local)" in said[0]
    assert "the run of --machine gpu" in said[0]
    gpu = resolve_share(tmp_path, PY, "gpu")  # the run that has c: the handler is its own
    assert not [w for w in gpu.warnings if "handler" in w], gpu.warnings


@pytest.mark.parametrize(
    ("share", "message"),
    [
        ("robt", r"--machine robt: the launch declares no machine 'robt' \(declared: gpu, robot\)"),
        ("local", r"declares a machine named 'local'"),
    ],
)
def test_a_share_the_launch_does_not_have_is_refused(
    tmp_path: Path, share: str, message: str
) -> None:
    text = PY.replace('name="gpu"', 'name="local"').replace('machine="gpu"', 'machine="local"')
    if share == "robt":
        text = PY
    with pytest.raises(MlaunchError, match=message):
        resolve_share(tmp_path, text, share)


ROS1 = """<launch>
  <machine name="robot" address="robot-alias" env-loader="/opt/env.sh"/>
  <node pkg="mlaunch_demo" type="talker" name="first"/>
  <group ns="g">
    <machine name="gpu" address="gpu-alias" default="true"/>
    <node pkg="mlaunch_demo" type="talker" name="a"/>
    <node pkg="mlaunch_demo" type="talker" name="b" machine="robot"/>
  </group>
  <node pkg="mlaunch_demo" type="talker" name="c"/>
  <machine name="never" address="never-alias" default="never"/>
  <node pkg="mlaunch_demo" type="talker" name="d"/>
</launch>
"""


def test_ros1_machines_split_by_roslaunchs_rules(tmp_path: Path) -> None:
    # roslaunch 1.15: default="true" gives its machine to the nodes after it that name none,
    # in the file's order: past the end of its <group> too (the loader hands the default back
    # up); default="never" does not take it over; machine= wins.
    shares = {}
    for share in ("local", "gpu", "robot"):
        plan = resolve_share(tmp_path, ROS1, share, suffix="launch")
        shares[share] = sorted(str(s.node.name) for s in plan.processes() if s.node is not None)
    whole = resolve_share(tmp_path, ROS1, None, suffix="launch")
    placed = {
        str(s.node.name): s.machine.name if s.machine else "local"
        for s in whole.processes()
        if s.node is not None
    }
    for share, names in shares.items():
        assert names == sorted(n for n, m in placed.items() if m == share), (shares, placed)
    assert placed == {"first": "local", "a": "gpu", "b": "robot", "c": "gpu", "d": "gpu"}
    robot = resolve_share(tmp_path, ROS1, "robot", suffix="launch").processes()
    assert robot[0].argv[0] == "/opt/env.sh"
    assert robot[0].argv[1] == str(EXAMPLES_PREFIX / "lib" / "mlaunch_demo" / "talker")


def test_print_of_a_share_and_its_json(tmp_path: Path) -> None:
    path = tmp_path / "m.launch.py"
    path.write_text(PY)
    text = run_mlaunch(str(path), "--print", "--machine", "gpu", env=clean_env())
    assert text.returncode == 0, text.stderr
    assert "Plan for" in text.stdout and "1 process(es) at start" in text.stdout
    assert "elsewhere: a-1 is given no machine: not started by this run" in text.stdout
    assert "elsewhere: b-2 runs on robot: not started by this run" in text.stdout
    assert "machine: gpu (this computer: gpu-alias)" in text.stdout
    data = run_mlaunch(str(path), "--print", "--format", "json", "--machine", "gpu",
                       env=clean_env())  # fmt: skip
    assert data.returncode == 0, data.stderr
    steps = json.loads(data.stdout)["steps"]
    kinds = [(s["kind"], s.get("label"), s.get("share")) for s in steps if s["kind"] != "handler"]
    assert kinds == [
        ("elsewhere", "a-1", "local"),
        ("elsewhere", "b-2", "robot"),
        ("process", "c-3", None),
        ("elsewhere", "d-4", "robot"),
    ]


def test_ros1_native_runs_are_not_split(tmp_path: Path) -> None:
    path = tmp_path / "m.launch"
    path.write_text(ROS1)
    done = run_mlaunch(str(path), "--ros1", "--machine", "gpu", env=clean_env())
    assert done.returncode == 2, done.stderr
    assert "a native ROS 1 run" in done.stderr and "--ros2" in done.stderr


def test_a_share_runs_only_its_processes_without_ssh(tmp_path: Path) -> None:
    # The machine's address is an ssh alias nobody defined: any ssh attempt would fail the run.
    loader = tmp_path / "env.sh"
    loader.write_text('#!/bin/sh\nexport VIA_LOADER=yes\nexec "$@"\n')
    loader.chmod(0o755)
    said = tmp_path / "said"
    said.mkdir()
    write = (
        "import os, sys; open(os.path.join(sys.argv[1], sys.argv[2]), 'w')"
        ".write(os.environ.get('VIA_LOADER', 'no') + ' ' + os.environ.get('SET_BY_LAUNCH', ''))"
    )
    path = tmp_path / "share.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess, SetEnvironmentVariable\n"
        "from mlaunch.actions import Machine\n"
        "def p(name, **kw):\n"
        f"    return ExecuteProcess(cmd=[{sys.executable!r}, '-c', {write!r}, {str(said)!r},"
        " name], name=name, **kw)\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        f"        Machine(name='robot', address='no-such-alias.invalid', env_loader={str(loader)!r}),\n"
        "        SetEnvironmentVariable('SET_BY_LAUNCH', 'set'),\n"
        "        p('here'), p('there', machine='robot'), p('there2', machine='robot'),\n"
        "    ])\n"
    )
    done = run_mlaunch(str(path), "--machine", "robot", env=clean_env())
    assert done.returncode == 0, done.stdout + done.stderr
    assert sorted(os.listdir(said)) == ["there", "there2"]
    assert (said / "there").read_text() == "yes set"  # env-loader, then what the launch set
    # the labels are the whole launch's
    assert "[there-2]" in done.stdout + done.stderr or "there-2" in done.stdout + done.stderr
    done = run_mlaunch(str(path), "--machine", "local", env=clean_env())
    assert done.returncode == 0, done.stdout + done.stderr
    assert sorted(os.listdir(said)) == ["here", "there", "there2"]
    assert (said / "here").read_text() == "no set"


COMPOSED = """
from launch import LaunchDescription
from launch_ros.actions import ComposableNodeContainer, LoadComposableNodes
from launch_ros.descriptions import ComposableNode
from mlaunch.actions import Machine

def generate_launch_description():
    return LaunchDescription([
        Machine(name="gpu", address="gpu-alias"),
        ComposableNodeContainer(
            name="box", namespace="", package="rclcpp_components",
            executable="component_container", machine="gpu",
            composable_node_descriptions=[
                ComposableNode(package="demo", plugin="demo::Talker", name="talker")]),
        LoadComposableNodes(target_container="/elsewhere_box", composable_node_descriptions=[
            ComposableNode(package="demo", plugin="demo::Listener", name="listener")]),
    ])
"""


def test_a_load_is_done_by_the_run_that_starts_its_container(tmp_path: Path) -> None:
    def loads(plan: Plan) -> tuple[list[str], list[str | None]]:
        here = [str(getattr(s, "target", "")) for s in plan.steps if hasattr(s, "requests")]
        there = [s.container for s in plan.steps if isinstance(s, Elsewhere) and s.step]
        return here, there

    gpu = resolve_share(tmp_path, COMPOSED, "gpu")
    local = resolve_share(tmp_path, COMPOSED, "local")
    # the container's own share loads into it; a container the launch does not start: local
    assert loads(gpu) == (["/box"], ["/elsewhere_box"])
    assert loads(local) == (["/elsewhere_box"], ["/box"])
    assert [s.label for s in gpu.processes()] == ["component_container-1"]
    assert local.processes() == []


def test_ros1_default_machine_holds_past_an_include(tmp_path: Path) -> None:
    (tmp_path / "inc.launch").write_text(
        '<launch>\n  <machine name="gpu" address="gpu-alias" default="true"/>\n'
        '  <node pkg="mlaunch_demo" type="talker" name="inside"/>\n</launch>\n'
    )
    text = (
        '<launch>\n  <node pkg="mlaunch_demo" type="talker" name="before"/>\n'
        '  <include file="$(dirname)/inc.launch"/>\n'
        '  <node pkg="mlaunch_demo" type="talker" name="after"/>\n</launch>\n'
    )
    plan = resolve_share(tmp_path, text, None, suffix="launch")
    placed = {
        str(s.node.name): s.machine.name if s.machine else "local"
        for s in plan.processes()
        if s.node is not None
    }
    assert placed == {"before": "local", "inside": "gpu", "after": "gpu"}  # as roslaunch 1.15


def test_a_shares_print_matches_what_the_ssh_path_prints_for_its_node(tmp_path: Path) -> None:
    # The same node, as the launcher would start it over ssh (--print of the whole launch) and
    # as its machine's share starts it here: the same parameters, remaps, names and launch-set
    # environment; argv differs only by the env-loader in front and the program found here.
    path = tmp_path / "node.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import SetEnvironmentVariable\n"
        "from launch_ros.actions import Node, SetParameter\n"
        "from mlaunch.actions import Machine\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        "        Machine(name='robot', address='robot-alias', env_loader='/opt/env.sh'),\n"
        "        SetEnvironmentVariable('SET_BY_LAUNCH', 'set'), SetParameter('g', 2.5),\n"
        "        Node(package='mlaunch_demo', executable='talker', name='t', namespace='r',\n"
        "             machine='robot', parameters=[{'rate': 5, 'frame': 'base'}],\n"
        "             remappings=[('a', 'b')], arguments=['x y']),\n"
        "    ])\n"
    )
    env = clean_env(AMENT_PREFIX_PATH=str(EXAMPLES_PREFIX))

    def process(*extra: str) -> dict[str, object]:
        done = run_mlaunch(str(path), "--print", "--format", "json", *extra, env=env)
        assert done.returncode == 0, done.stderr
        steps = json.loads(done.stdout)["steps"]
        found: dict[str, object] = next(s for s in steps if s["kind"] == "process")
        return found

    over_ssh, share = process(), process("--machine", "robot")
    for key in ("label", "parameters", "remaps", "node", "env", "cwd", "respawn", "stop"):
        assert share[key] == over_ssh[key], key
    program = str(EXAMPLES_PREFIX / "lib" / "mlaunch_demo" / "talker")
    assert share["argv"] == ["/opt/env.sh", program, *over_ssh["argv"][1:]]  # type: ignore[index]
    assert over_ssh["machine"]["local"] is False and share["machine"]["local"] is True  # type: ignore[index]
