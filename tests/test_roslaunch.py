"""The roslaunch frontend: ROS 1 .launch files resolved on ROS 2 semantics.

Pure tests: each ROS 1 file is written inline, loaded and resolved to a plan (nothing runs).
Nodes come from the example ament prefix (launches/examples/prefix: mlaunch_demo talker and
listener), so the command lines are the real ones, not stand-ins.
"""

from __future__ import annotations

import os
import re
import textwrap
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from mlaunch import readers
from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.steps import Plan, ProcessSpec
from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve
from mlaunch.ros import packages

REPO = Path(__file__).resolve().parent.parent
PREFIX = REPO / "launches" / "examples" / "prefix"
DEMO = str(PREFIX / "lib" / "mlaunch_demo")
ENV = {"PATH": os.environ["PATH"], "HOME": "/home/ros1", "AMENT_PREFIX_PATH": str(PREFIX)}
_ANON = re.compile(r"_[A-Za-z0-9_]+_\d+_\d+$")


# --- helpers (test_convert.py uses them too) ----------------------------------------------------


@pytest.fixture(autouse=True)
def fresh_packages(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Package lookups see this test's files and environment only."""
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(PREFIX))
    packages.forget_scans()
    yield
    packages.forget_scans()


def write(folder: Path, name: str, body: str) -> str:
    """A file in ``folder`` (a source tree: COLCON_IGNORE marks its root for $(find))."""
    (folder / "COLCON_IGNORE").touch()
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(body).lstrip())
    return str(path)


def package(folder: Path, name: str) -> Path:
    """A source package ``name`` under ``folder``."""
    root = folder / name
    root.mkdir(parents=True, exist_ok=True)
    (root / "package.xml").write_text(
        f'<?xml version="1.0"?><package format="2"><name>{name}</name><version>0.0.0</version>'
        "<description>test</description><maintainer email='t@e.st'>t</maintainer>"
        "<license>BSD</license></package>"
    )
    return root


def plan_of(
    path: str, args: dict[str, str] | None = None, temp: Path | None = None, **env: str
) -> Plan:
    """Load and resolve a launch file (any format) with the example prefix installed."""
    temp_dir = temp or Path(path).parent / "params"
    temp_dir.mkdir(exist_ok=True)
    return resolve(
        readers.load(path),
        path=path,
        arguments=args or {},
        environ={**ENV, **env},
        options=ResolveOptions(temp_dir=str(temp_dir)),
        labels=LabelCounter(),
    )


def summarize(plan: Plan) -> list[dict[str, Any]]:
    """The processes as a run depends on them; params files written for a node by content.

    Consecutive params files are merged (rcl applies them in order): ROS 2's XML and YAML give
    each <param> its own file where Python gives a dict one, with the same meaning.
    """
    return [
        {
            "label": spec.label,
            "argv": _argv(spec, plan.temp_dir or ""),
            "env_changes": spec.env_changes,
            "cwd": spec.cwd,
            "output": spec.output,
            "respawn": spec.respawn,
            "required": spec.required,
            "node": _node(spec),
            "standin": spec.standin,
        }
        for spec in plan.processes()
    ]


def _node(spec: ProcessSpec) -> tuple[Any, ...] | None:
    node = spec.node
    if node is None:
        return None
    name = None if node.name is None else _ANON.sub("_<anon>", node.name)
    return (name, node.namespace, node.package, node.executable, node.lifecycle)


def _argv(spec: ProcessSpec, temp_dir: str) -> list[Any]:
    out: list[Any] = []
    merged: dict[str, Any] | None = None
    args = list(spec.argv)
    i = 0
    while i < len(args):
        if args[i] == "--params-file" and args[i + 1].startswith(temp_dir + os.sep):
            content = yaml.safe_load(Path(args[i + 1]).read_text())
            if merged is None:
                merged = {}
                out += ["--params-file", merged]
            for key, value in content.items():
                merged.setdefault(key, {}).update(value["ros__parameters"])
            i += 2
            continue
        merged = None
        out.append(_ANON.sub("_<anon>", args[i]))
        i += 1
    return out


def params(spec: ProcessSpec) -> dict[str, Any]:
    """The parameters a node's own params files give it (all files merged)."""
    found: dict[str, Any] = {}
    for i, item in enumerate(spec.argv[:-1]):
        if item == "--params-file":
            for value in yaml.safe_load(Path(spec.argv[i + 1]).read_text()).values():
                found.update(value["ros__parameters"])
    return found


def globals_of(spec: ProcessSpec) -> dict[str, str]:
    """The ``-p name:=value`` rules (SetParameter globals) of a node."""
    rules = [spec.argv[i + 1] for i, a in enumerate(spec.argv[:-1]) if a == "-p"]
    return dict(rule.split(":=", 1) for rule in rules)


def by_label(plan: Plan) -> dict[str, ProcessSpec]:
    return {spec.label.rsplit("-", 1)[0]: spec for spec in plan.processes()}


def warnings_text(plan: Plan) -> str:
    return "\n".join(plan.warnings)


# --- arguments and substitutions -----------------------------------------------------------------


def test_args_defaults_constants_and_command_line(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "a.launch",
        """
        <launch>
          <arg name="robot" default="r1" doc="which robot"/>
          <arg name="fixed" value="const"/>
          <arg name="speed" default="$(arg robot)-fast"/>
          <node pkg="mlaunch_demo" type="talker" name="t" args="$(arg robot) $(arg fixed) $(arg speed)"/>
        </launch>
        """,
    )
    (talker,) = plan_of(path).processes()
    assert talker.argv[:4] == (f"{DEMO}/talker", "r1", "const", "r1-fast")
    plan = plan_of(path, {"robot": "r7", "fixed": "other"})
    assert plan.processes()[0].argv[1:4] == ("r7", "const", "r7-fast")
    assert "arg 'fixed' has a fixed value" in warnings_text(plan)
    assert plan.arguments["robot"].description == "which robot"


def test_required_arg_and_undeclared_arg_are_errors_with_the_line(tmp_path: Path) -> None:
    path = write(tmp_path, "req.launch", '<launch>\n  <arg name="must"/>\n</launch>\n')
    with pytest.raises(MlaunchError, match="Required launch argument 'must'"):
        plan_of(path)
    assert plan_of(path, {"must": "x"}).processes() == []
    bad = write(
        tmp_path,
        "undeclared.launch",
        '<launch>\n  <node pkg="mlaunch_demo" type="talker" name="t" args="$(arg nope)"/>\n'
        "</launch>\n",
    )
    with pytest.raises(MlaunchError) as caught:
        readers.load(bad)
    assert str(caught.value).startswith(f"{bad}:2:")
    assert "arg 'nope' is not defined" in str(caught.value)


def test_env_optenv_anon_dirname_and_find(tmp_path: Path) -> None:
    package(tmp_path, "demo_cfg")
    path = write(
        tmp_path,
        "launch/s.launch",
        """
        <launch>
          <node pkg="mlaunch_demo" type="talker" name="$(anon talker)"
                args="$(env HOME) $(optenv NOT_SET_X a b c) $(optenv NOT_SET_X) $(dirname) $(find demo_cfg)/x.yaml"/>
        </launch>
        """,
    )
    (talker,) = plan_of(path).processes()
    # roslaunch substitutes, then splits like a shell: words split, an empty one disappears
    assert talker.argv[1:7] == (
        "/home/ros1",
        "a",
        "b",
        "c",
        str(tmp_path / "launch"),
        f"{tmp_path / 'demo_cfg'}/x.yaml",
    )
    assert re.fullmatch(r"__node:=talker_\w+", talker.argv[talker.argv.index("-r") + 1])


def test_eval_types_arguments_as_roslaunch_does(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "e.launch",
        """
        <launch>
          <arg name="n" default="3"/>
          <arg name="flag" default="false"/>
          <arg name="word" default="abc"/>
          <node pkg="mlaunch_demo" type="talker" name="t">
            <param name="sum" value="$(eval n + 2)"/>
            <param name="twice" value="$(eval arg('word') * 2)"/>
            <param name="neither" value="$(eval not flag and word == 'abc')"/>
            <param name="home" value="$(eval env('HOME') + '/x')"/>
          </node>
        </launch>
        """,
    )
    (talker,) = plan_of(path).processes()
    assert params(talker) == {"sum": 5, "twice": "abcabc", "neither": True, "home": "/home/ros1/x"}
    (talker,) = plan_of(path, {"n": "1.5", "flag": "True"}).processes()
    assert params(talker)["sum"] == 3.5 and params(talker)["neither"] is False


@pytest.mark.parametrize(
    ("attribute", "message"),
    [
        ('args="x $(eval 1 + 1)"', "must be the whole attribute value"),
        ("args=\"$(eval __import__('os'))\"", "double underscore"),
        ('args="$(eval nope + 1)"', "'nope' is neither a declared arg"),
        ('args="$(eval 1 +)"', "Python syntax error"),
        ('args="$(what x)"', "unknown substitution $(what)"),
        ('args="$(find)"', "$(find) takes 1 argument"),
        ('if="maybe"', "if='maybe' is not a boolean"),
        ('if="true" unless="false"', "cannot set both 'if' and 'unless'"),
        ('respawn="true" required="true"', "respawn and required cannot both be set"),
        ('output="loud"', "output='loud' is not valid; valid: log, screen"),
    ],
)
def test_bad_node_attributes_are_located_errors(
    tmp_path: Path, attribute: str, message: str
) -> None:
    path = write(
        tmp_path,
        "bad.launch",
        f'<launch>\n\n  <node pkg="mlaunch_demo" type="talker" name="t" {attribute}/>\n</launch>\n',
    )
    with pytest.raises(MlaunchError) as caught:
        readers.load(path)
    assert str(caught.value).startswith(f"{path}:3:"), str(caught.value)
    assert message in str(caught.value)


def test_malformed_xml_is_an_error(tmp_path: Path) -> None:
    # <machine> and machine= are mlaunch.machines': tests/test_machines_resolve.py.
    broken = write(tmp_path, "x.launch", "<launch>\n  <node name='a'>\n</launch>\n")
    with pytest.raises(MlaunchError, match=r"x\.launch:3: malformed XML"):
        readers.load(broken)


# --- parameters ---------------------------------------------------------------------------------


def test_private_params_are_typed_as_roslaunch_types_them(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "p.launch",
        """
        <launch>
          <node pkg="mlaunch_demo" type="talker" name="t">
            <param name="i" value="20"/>
            <param name="f" value="20.0"/>
            <param name="b" value="True"/>
            <param name="s" value="yes"/>
            <param name="e" value="1e3"/>
            <param name="d" type="double" value="3"/>
            <param name="forced" type="str" value="true"/>
            <param name="~priv" value=" padded "/>
            <param name="ns/inner" type="int" value="4"/>
            <param name="y" type="yaml" value="{a: 1, b: [1.5, 2]}"/>
          </node>
        </launch>
        """,
    )
    (talker,) = plan_of(path).processes()
    assert params(talker) == {
        "i": 20,
        "f": 20.0,
        "b": True,
        "s": "yes",
        "e": "1e3",  # roslaunch: no '.', so not a float
        "d": 3.0,
        "forced": "true",
        "priv": "padded",
        "ns.inner": 4,
        "y.a": 1,
        "y.b": [1.5, 2.0],
    }


def test_bad_param_value_for_its_type_is_a_located_error(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "t.launch",
        '<launch>\n  <param name="x" type="int" value="many"/>\n</launch>\n',
    )
    with pytest.raises(MlaunchError, match=r"t\.launch:2: <param>: param value 'many' is not of"):
        readers.load(path)


def test_rosparam_files_inline_yaml_subst_value_and_angles(tmp_path: Path) -> None:
    cfg = package(tmp_path, "cfg_pkg")
    (cfg / "ctrl.yaml").write_text(
        "rate: 20\ngains: {kp: 1.5, ki: 0}\nname: $(arg robot)\nturn: deg(180)\n"
    )
    path = write(
        tmp_path,
        "launch/r.launch",
        """
        <launch>
          <arg name="robot" default="r1"/>
          <node pkg="mlaunch_demo" type="talker" name="t">
            <rosparam file="$(find cfg_pkg)/ctrl.yaml" command="load" subst_value="true"/>
            <rosparam ns="extra">
              half: rad(pi/2)
              names: [a, b]
            </rosparam>
            <rosparam param="only">[1, 2, 3]</rosparam>
          </node>
        </launch>
        """,
    )
    (talker,) = plan_of(path, {"robot": "r5"}).processes()
    found = params(talker)
    assert found["rate"] == 20 and found["gains.kp"] == 1.5 and found["gains.ki"] == 0
    assert found["name"] == "r5"
    assert found["turn"] == pytest.approx(3.141592653589793)
    assert found["extra.half"] == pytest.approx(1.5707963267948966)
    assert found["extra.names"] == ["a", "b"] and found["only"] == [1, 2, 3]


def test_rosparam_dump_delete_and_unusable_values_are_warnings(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "w.launch",
        """
        <launch>
          <rosparam command="dump" file="/tmp/out.yaml"/>
          <node pkg="mlaunch_demo" type="talker" name="t">
            <rosparam>{empty: [], nothing: null}</rosparam>
            <param name="blob" binfile="/etc/hostname"/>
          </node>
        </launch>
        """,
    )
    plan = plan_of(path)
    text = warnings_text(plan)
    assert "w.launch:2: <rosparam command='dump'> is skipped" in text
    assert "w.launch:3: <rosparam> at line 4: parameter empty: an empty list has no ROS 2" in text
    assert "w.launch:3: <param> at line 5: <param binfile> (binary data" in text


def test_global_params_reach_every_node_of_their_scope_whatever_the_order(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "g.launch",
        """
        <launch>
          <arg name="sim" default="false"/>
          <node pkg="mlaunch_demo" type="talker" name="first"/>
          <param name="/use_sim_time" value="$(arg sim)"/>
          <param name="rate" value="5"/>
          <group ns="robot">
            <param name="local" value="1"/>
            <node pkg="mlaunch_demo" type="listener" name="inside"/>
          </group>
          <group if="$(arg sim)">
            <param name="sim_only" value="on"/>
          </group>
          <node pkg="mlaunch_demo" type="listener" name="last" ns="other"/>
        </launch>
        """,
    )
    nodes = {s.node.name: s for s in plan_of(path).processes() if s.node}
    assert globals_of(nodes["first"]) == {"use_sim_time": "False", "rate": "5"}
    assert globals_of(nodes["inside"]) == {"use_sim_time": "False", "rate": "5", "local": "1"}
    assert globals_of(nodes["last"]) == {"use_sim_time": "False", "rate": "5"}
    nodes = {s.node.name: s for s in plan_of(path, {"sim": "true"}).processes() if s.node}
    # a <group if> without ns is no parameter scope in ROS 1: its param reaches the others too
    # roslaunch keeps "on" as text, and so does the node: quoted, as rcl would read a bool
    assert globals_of(nodes["first"]) == {"use_sim_time": "True", "rate": "5", "sim_only": "'on'"}


def test_robot_description_goes_to_robot_state_publisher_only(tmp_path: Path) -> None:
    bot = package(tmp_path, "bot")
    (bot / "bot.urdf").write_text('<robot name="bot"><link name="base"/></robot>\n')
    path = write(
        tmp_path,
        "launch/rd.launch",
        """
        <launch>
          <param name="robot_description" textfile="$(find bot)/bot.urdf"/>
          <node pkg="mlaunch_demo" type="talker" name="other"/>
          <node pkg="robot_state_publisher" type="state_publisher" name="rsp">
            <param name="publish_frequency" type="double" value="20"/>
            <param name="tf_prefix" value="old"/>
          </node>
        </launch>
        """,
    )
    from mlaunch.ros1 import model, reading

    model_items = reading.read(path)
    rsp = next(i for i in model_items if isinstance(i, model.NodeItem) and i.name == ("rsp",))
    assert rsp.executable == ("robot_state_publisher",)
    names = [model.static_text(n) for n, _ in rsp.parameters]
    assert names == ["robot_description", "publish_frequency"]
    other = next(i for i in model_items if isinstance(i, model.NodeItem) and i.name == ("other",))
    assert other.parameters == []
    assert not any(isinstance(i, model.SetParam) for i in model_items)
    assert any("tf_prefix of ROS 1 robot_state_publisher" in w for w in rsp.warnings)


def test_unconsumed_robot_description_and_starved_rsp_are_warnings(tmp_path: Path) -> None:
    from mlaunch.ros1 import model, reading

    lone = write(
        tmp_path,
        "lone.launch",
        '<launch>\n  <param name="robot_description" value="&lt;robot/&gt;"/>\n</launch>\n',
    )
    (warning,) = reading.read(lone)
    assert isinstance(warning, model.Warn)
    assert "no robot_state_publisher of this file's scope takes it" in warning.message
    starved = write(
        tmp_path,
        "starved.launch",
        '<launch>\n  <node pkg="robot_state_publisher" type="robot_state_publisher" name="r"/>\n'
        "</launch>\n",
    )
    (node,) = reading.read(starved)
    # a note for conversions: a run gives the node what the parameter server holds
    assert "robot_state_publisher gets no robot_description" in node.scope_notes[0]


# --- nodes, scopes, includes ------------------------------------------------------------------


def test_node_attributes_remaps_env_and_namespaces(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "n.launch",
        """
        <launch>
          <arg name="ns" default="team"/>
          <remap from="chatter" to="chat"/>
          <env name="GLOBAL_ENV" value="g"/>
          <group ns="$(arg ns)">
            <node pkg="mlaunch_demo" type="talker" name="t" ns="sub" output="screen"
                  respawn="true" respawn_delay="1.5" launch-prefix="nice -n 3" args="-x 'a b'">
              <remap from="in" to="/abs/in"/>
              <env name="NODE_ENV" value="1"/>
            </node>
          </group>
          <node pkg="mlaunch_demo" type="listener" name="l" required="true" cwd="node" clear_params="true"/>
        </launch>
        """,
    )
    plan = plan_of(path)
    talker, listener = plan.processes()
    assert talker.argv == (
        "nice",
        "-n",
        "3",
        f"{DEMO}/talker",
        "-x",
        "a b",
        "--ros-args",
        "-r",
        "__node:=t",
        "-r",
        "__ns:=/team/sub",
        "-r",
        "chatter:=chat",
        "-r",
        "in:=/abs/in",
    )
    assert talker.output == "screen" and talker.respawn.mode == "always"
    assert talker.respawn.delay == 1.5
    assert talker.env_changes["GLOBAL_ENV"] == "g" and talker.env_changes["NODE_ENV"] == "1"
    assert listener.required and "NODE_ENV" not in listener.env_changes
    assert listener.node is not None and listener.node.namespace == "/"
    text = warnings_text(plan)
    assert "n.launch:12: cwd='node' is not kept" in text
    assert "n.launch:12: clear_params has no effect in ROS 2" in text


def test_include_passes_args_in_a_namespace_and_dirname_points_at_the_included_file(
    tmp_path: Path,
) -> None:
    write(
        tmp_path,
        "parts/part.launch",
        """
        <launch>
          <arg name="who"/>
          <arg name="speed" default="1"/>
          <node pkg="mlaunch_demo" type="listener" name="part" args="$(arg who) $(arg speed) $(dirname)"/>
        </launch>
        """,
    )
    path = write(
        tmp_path,
        "main.launch",
        """
        <launch>
          <arg name="robot" default="r1"/>
          <include file="$(dirname)/parts/part.launch" ns="$(arg robot)" if="true">
            <arg name="who" value="$(arg robot)"/>
            <env name="INC_ENV" value="yes"/>
          </include>
          <include file="$(dirname)/parts/part.launch" unless="true">
            <arg name="who" value="never"/>
          </include>
          <include file="$(dirname)/parts/part.launch" ns="twice">
            <arg name="who" value="again"/>
            <arg name="speed" value="2" if="false"/>
          </include>
        </launch>
        """,
    )
    plan = plan_of(path, {"robot": "r3"})
    part, again = plan.processes()
    assert again.argv[1:3] == ("again", "2")  # a launch argument cannot be conditional in ROS 2
    assert "main.launch:10: <arg> at line 12: if/unless on an <include>'s <arg>" in "\n".join(
        plan.warnings
    )
    assert part.argv[1:4] == ("r3", "1", str(tmp_path / "parts"))
    assert part.node is not None and part.node.fully_qualified_name == "/r3/part"
    assert part.env_changes["INC_ENV"] == "yes"


def test_skipped_and_unknown_tags_and_attributes_are_warnings(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "u.launch",
        """
        <launch deprecated="use new.launch">
          <test test-name="check" pkg="mlaunch_demo" type="talker"/>
          <master auto="start"/>
          <frobnicate/>
          <node pkg="mlaunch_demo" type="talker" name="t" colour="red">
            <arg name="x"/>
          </node>
        </launch>
        """,
    )
    text = warnings_text(plan_of(path))
    for expected in (
        "u.launch:1: this launch file is deprecated: use new.launch",
        "u.launch:2: rostest <test test-name='check'> is skipped",
        "u.launch:3: <master> is ignored",
        "u.launch:4: unrecognized tag <frobnicate> is ignored",
        "u.launch:5: unknown attribute 'colour' of <node> is ignored",
        "u.launch:6: <arg> is not valid inside <node>",
    ):
        assert expected in text


# --- known ROS 1 programs ---------------------------------------------------------------------


def _fake_tf2_ros(tmp_path: Path) -> str:
    """An ament prefix with tf2_ros installed (the program just exists)."""
    prefix = tmp_path / "tf_prefix"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "tf2_ros").touch()
    program = prefix / "lib" / "tf2_ros" / "static_transform_publisher"
    program.parent.mkdir(parents=True)
    program.write_text("#!/bin/sh\n")
    program.chmod(0o755)
    (prefix / "share" / "tf2_ros").mkdir(parents=True)
    return f"{prefix}{os.pathsep}{PREFIX}"


STATIC_TF = """
<launch>
  <node pkg="tf" type="static_transform_publisher" name="euler"
        args="1 2 3 0.1 0.2 0.3 /base_link /laser 100"/>
  <node pkg="tf2_ros" type="static_transform_publisher" name="quat"
        args="0 0 0 0 0 0 1 map odom"/>
</launch>
"""


def test_static_transforms_become_tf2_ros_options_where_tf2_ros_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    prefixes = _fake_tf2_ros(tmp_path)
    monkeypatch.setenv("AMENT_PREFIX_PATH", prefixes)
    packages.forget_scans()
    path = write(tmp_path, "tf.launch", STATIC_TF)
    plan = plan_of(path, AMENT_PREFIX_PATH=prefixes)
    euler, quat = plan.processes()
    program = str(tmp_path / "tf_prefix" / "lib" / "tf2_ros" / "static_transform_publisher")
    assert euler.argv[: euler.argv.index("--ros-args")] == (
        program,
        *("--x", "1", "--y", "2", "--z", "3", "--yaw", "0.1", "--pitch", "0.2", "--roll", "0.3"),
        *("--frame-id", "base_link", "--child-frame-id", "laser"),
    )
    assert quat.argv[1:19:2] == ("--x", "--y", "--z", "--qx", "--qy", "--qz", "--qw",
                                 "--frame-id", "--child-frame-id")  # fmt: skip
    text = warnings_text(plan)
    assert (
        "tf.launch:2: the period (100 ms) of ROS 1 tf static_transform_publisher is dropped" in text
    )
    assert "tf.launch:2: frame ids lose their leading '/'" in text


def test_static_transforms_without_tf2_ros_or_tf2_msgs_are_dropped_with_a_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from mlaunch import standins

    # As on a machine where scripts/setup could not build tf2_msgs.
    monkeypatch.setattr(standins, "NEEDS", {"stp": "mlaunch_test_no_such_module"})
    path = write(tmp_path, "tf.launch", STATIC_TF)
    plan = plan_of(path)
    assert plan.processes() == []
    text = warnings_text(plan)
    assert "tf.launch:2: tf2_ros static_transform_publisher is not installed" in text
    assert "stand-in for it needs tf2_msgs (./scripts/setup builds it)" in text
    assert "base_link -> laser is not published" in text
    assert "tf.launch:4: tf2_ros static_transform_publisher is not installed" in text


def test_static_transforms_run_as_the_standin_without_tf2_ros(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from mlaunch import standins

    monkeypatch.setattr(standins, "NEEDS", {})  # the stand-in counts as usable here
    path = write(tmp_path, "tf.launch", STATIC_TF)
    euler, quat = plan_of(path).processes()
    assert euler.standin == quat.standin == "tf2_ros/static_transform_publisher"
    assert euler.argv[1:3] == ("-m", "mlaunch.standins.stp")
    assert euler.argv[3 : euler.argv.index("--ros-args")] == (
        *("--x", "1", "--y", "2", "--z", "3", "--yaw", "0.1", "--pitch", "0.2", "--roll", "0.3"),
        *("--frame-id", "base_link", "--child-frame-id", "laser"),
    )


def test_joint_state_publisher_use_gui_chooses_the_gui_package(tmp_path: Path) -> None:
    from mlaunch.ros1 import model, reading

    path = write(
        tmp_path,
        "j.launch",
        """
        <launch>
          <arg name="gui" default="false"/>
          <param name="use_gui" value="$(arg gui)"/>
          <node pkg="joint_state_publisher" type="joint_state_publisher" name="jsp"/>
          <group ns="fixed">
            <node pkg="joint_state_publisher" type="joint_state_publisher" name="jsp">
              <param name="use_gui" value="true"/>
            </node>
          </group>
        </launch>
        """,
    )
    items = reading.read(path)
    switch = items[1]
    assert isinstance(switch, model.Group) and switch.warnings
    plain, gui = switch.items
    assert isinstance(plain, model.NodeItem) and isinstance(gui, model.NodeItem)
    assert plain.executable == ("joint_state_publisher",)
    assert plain.condition == model.Cond((model.ArgRef("gui"),), unless=True)
    assert gui.executable == ("joint_state_publisher_gui",)
    assert gui.condition == model.Cond((model.ArgRef("gui"),))
    group = items[2]
    assert isinstance(group, model.Group)
    (fixed,) = group.items
    assert isinstance(fixed, model.NodeItem)
    assert fixed.package == ("joint_state_publisher_gui",) and fixed.parameters == []
    assert not any(isinstance(i, model.SetParam) for i in items)  # use_gui was consumed


def test_rviz_and_arbotix_map_to_ros2_programs(tmp_path: Path) -> None:
    from mlaunch.ros1 import model, reading

    cfg = package(tmp_path, "viz")
    (cfg / "old.rviz").write_text("Panels:\n  - Class: rviz/Displays\n")
    (cfg / "new.rviz").write_text("Panels:\n  - Class: rviz_common/Displays\n")
    (cfg / "robot.urdf.xacro").write_text('<robot name="r"/>\n')
    path = write(
        tmp_path,
        "launch/v.launch",
        """
        <launch>
          <param name="robot_description" command="$(find xacro)/xacro.py $(find viz)/robot.urdf.xacro"/>
          <node pkg="rviz" type="rviz" name="old" args="-d $(find viz)/old.rviz"/>
          <node pkg="rviz" type="rviz" name="new" args="-d $(find viz)/new.rviz"/>
          <node pkg="arbotix_python" type="arbotix_driver" name="arbotix" output="screen" respawn="true">
            <param name="sim" value="true"/>
          </node>
        </launch>
        """,
    )
    warning, old, new, sim, spawn = reading.read(path)
    assert isinstance(warning, model.Warn)  # no robot_state_publisher takes the description
    assert isinstance(old, model.NodeItem) and isinstance(new, model.NodeItem)
    assert old.package == old.executable == ("rviz2",)
    assert old.arguments[0] == ("-d",)
    assert any("is a ROS 1 RViz config" in w for w in old.warnings)
    assert not new.warnings
    assert isinstance(sim, model.ProcessItem) and sim.cmd[0] == ("gzserver",)
    assert sim.respawn is True and sim.output == ("screen",)
    assert "replaced by a Gazebo simulator" in sim.warnings[0]
    assert isinstance(spawn, model.NodeItem)
    assert [model.static_text(a) for a in spawn.arguments] == [
        "-topic",
        "robot_description",
        "-entity",
        "robot",  # the model file's name, robot.urdf.xacro
    ]


def test_xacro_commands_run_xacro_in_process(tmp_path: Path) -> None:
    from mlaunch.ros1 import build, reading
    from mlaunch.ros1.model import ArgRef, CommandRef, DeclareArg, NodeItem

    model = package(tmp_path, "bot")
    (model / "bot.urdf.xacro").write_text(
        '<robot name="bot" xmlns:xacro="http://ros.org/wiki/xacro">'
        '<xacro:property name="w" value="2"/><link name="base_${w}"/></robot>\n'
    )
    path = write(
        tmp_path,
        "launch/x.launch",
        """
        <launch>
          <arg name="model" default="$(find xacro)/xacro '$(find bot)/bot.urdf.xacro'"/>
          <param name="robot_description" command="$(arg model)"/>
          <node pkg="robot_state_publisher" type="robot_state_publisher" name="rsp"/>
        </launch>
        """,
    )
    (declare, rsp) = reading.read(path)
    assert isinstance(declare, DeclareArg) and declare.default is not None
    assert declare.default[0] == "xacro '"
    assert isinstance(rsp, NodeItem)
    value = rsp.parameters[0][1]
    assert value.dynamic == (CommandRef((ArgRef("model"),)),)
    assert value.vtype is str
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitutions import perform

    context = LaunchContext(environment=ENV)
    context.launch_configurations["model"] = f"xacro '{model}/bot.urdf.xacro'"
    with context.file_locals(path):
        urdf = perform(context, build.subs(value.dynamic))
    assert '<link name="base_2"/>' in urdf


def test_split_arguments_keeps_substitutions_whole() -> None:
    from mlaunch.ros1.model import ArgRef
    from mlaunch.ros1.values import split_arguments

    found = split_arguments(("-a ", ArgRef("x"), "/y 'q r' z", ArgRef("w")))
    assert found == [("-a",), (ArgRef("x"), "/y"), ("q r",), ("z", ArgRef("w"))]


def test_plan_summaries_compare_params_by_content(tmp_path: Path) -> None:
    """The helper the conversion tests rely on: two temp files with one content compare equal."""
    path = write(
        tmp_path,
        "c.launch",
        '<launch>\n  <node pkg="mlaunch_demo" type="talker" name="t">\n'
        '    <param name="a" value="1"/>\n  </node>\n</launch>\n',
    )
    first = summarize(plan_of(path, temp=tmp_path / "one"))
    second = summarize(plan_of(path, temp=tmp_path / "two"))
    assert first == second
    assert first[0]["argv"][-2:] == ["--params-file", {"/**": {"a": 1}}]
