"""The XML frontend: every tag builds the Python API's action, typing, and every error located."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import Any

import pytest

from mlaunch import readers
from mlaunch.launch import actions
from mlaunch.launch.conditions import IfCondition, UnlessCondition
from mlaunch.plan.errors import LaunchArgumentError, LaunchFileError, MlaunchError
from mlaunch.plan.steps import Log, Plan, RequestShutdown, StartTimer
from mlaunch.resolve.resolver import ResolveOptions, resolve

ENV = {"PATH": os.environ["PATH"], "HOME": "/home/u", "KEEP": "k"}


def write(tmp_path: Path, body: str, name: str = "t.launch.xml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(body).lstrip("\n"))
    return path


def load(tmp_path: Path, body: str, name: str = "t.launch.xml") -> actions.LaunchDescription:
    return readers.load(str(write(tmp_path, body, name)))


def plan_of(tmp_path: Path, body: str, **args: str) -> Plan:
    path = write(tmp_path, body)
    description = readers.load(str(path))
    return resolve(
        description, path=str(path), arguments=args, environ=ENV, options=ResolveOptions()
    )


def error(tmp_path: Path, body: str) -> LaunchFileError:
    path = write(tmp_path, body)
    with pytest.raises(LaunchFileError) as caught:
        readers.load(str(path))
    return caught.value


def logs(plan: Plan) -> list[str]:
    return [s.message for s in plan.steps if isinstance(s, Log)]


# --- core tags -------------------------------------------------------------------------------


def test_arg_with_default_description_and_choices(tmp_path: Path) -> None:
    ld = load(
        tmp_path,
        """
        <launch>
          <arg name="mode" default="sim" description="Where to run">
            <choice value="sim"/>
            <choice value="real"/>
          </arg>
          <arg name="robot"/>
        </launch>
        """,
    )
    mode, robot = ld.entities
    assert isinstance(mode, actions.DeclareLaunchArgument)
    assert mode.name == "mode" and mode.choices == ["sim", "real"]
    assert mode.description == "Where to run. Valid choices are: ['sim', 'real']"
    assert mode.origin.endswith("t.launch.xml:2")
    assert robot.default_value is None


def test_arg_choices_and_required_checked_when_resolving(tmp_path: Path) -> None:
    body = """
        <launch>
          <arg name="mode" default="sim"><choice value="sim"/><choice value="real"/></arg>
          <log message="mode=$(var mode)"/>
        </launch>
    """
    assert logs(plan_of(tmp_path, body, mode="real")) == ["mode=real"]
    with pytest.raises(LaunchArgumentError, match="not one of its choices: sim, real") as caught:
        plan_of(tmp_path, body, mode="fake")
    assert caught.value.where is not None and caught.value.where.endswith("t.launch.xml:2")
    with pytest.raises(LaunchArgumentError, match="'robot' was not provided"):
        plan_of(tmp_path, '<launch><arg name="robot"/></launch>')


def test_let_and_log(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <let name="who" value="world"/>
          <let name="greeting" value="hello $(var who)"/>
          <log message="$(var greeting)!"/>
        </launch>
        """,
    )
    assert logs(plan) == ["hello world!"]


def test_group_scoped_forwarding_and_keep(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <let name="outer" value="o"/>
          <group>
            <let name="inner" value="i"/>
            <set_env name="SCOPED" value="1"/>
            <log message="$(var outer)$(var inner)"/>
          </group>
          <log message="$(var inner gone) $(env SCOPED unset)"/>
          <group forwarding="false">
            <keep name="given" value="g$(var outer)"/>
            <log message="$(var outer hidden) $(var given)"/>
          </group>
          <group scoped="0"><let name="leak" value="yes"/></group>
          <log message="$(var leak)"/>
        </launch>
        """,
    )
    assert logs(plan) == ["oi", "gone unset", "hidden go", "yes"]


def test_include_passes_arg_and_let_and_crosses_formats(tmp_path: Path) -> None:
    write(
        tmp_path,
        """
        launch:
        - arg: {name: who}
        - arg: {name: extra, default: none}
        - log: {message: "included $(var who) $(var extra) from $(filename)"}
        """,
        "inner.launch.yaml",
    )
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <include file="$(dirname)/inner.launch.yaml">
            <arg name="who" value="me"/>
            <let name="extra" value="x"/>
          </include>
          <log message="after: $(var who)"/>
        </launch>
        """,
    )
    assert logs(plan) == [f"included me x from {tmp_path}/inner.launch.yaml", "after: me"]


def test_executable_every_attribute(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        f"""
        <launch>
          <executable cmd="sh -c 'echo $(var word) &quot;two words&quot;' --flag"
                      cwd="{tmp_path}" name="worker" output="screen" launch-prefix="nice -n 5"
                      respawn="true" respawn_delay="1.5" respawn_max_retries="3"
                      sigterm_timeout="2" sigkill_timeout="0.5" emulate_tty="true"
                      on_exit="shutdown">
            <env name="ROBOT" value="r$(var word)"/>
          </executable>
          <executable cmd="true" shell="true" respawn="on-failure" required="yes"/>
        </launch>
        """,
        word="1",
    )
    first, second = plan.processes()
    assert first.argv == ("nice", "-n", "5", "sh", "-c", 'echo 1 "two words"', "--flag")
    assert first.label == "worker-1" and first.cwd == str(tmp_path) and first.output == "screen"
    assert first.respawn.mode == "always" and first.respawn.delay == 1.5
    assert first.respawn.max_retries == 3
    assert (first.sigterm_timeout, first.sigkill_timeout) == (2.0, 0.5)
    assert first.env_changes["ROBOT"] == "r1"
    assert first.emulate_tty and "RCUTILS_COLORIZED_OUTPUT" not in first.env  # a pty, as launch
    assert first.required and first.on_exit is not None
    (shutdown,) = first.on_exit.entities
    assert isinstance(shutdown, actions.Shutdown) and shutdown.origin.endswith(":2")
    assert second.shell and second.respawn.mode == "on-failure" and second.required
    assert second.label == "true-2"


def test_cmd_splitting_with_substitutions_and_quotes(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <let name="d" value="/opt/x"/>
          <executable cmd="echo $(var d)/bin a'$(var d) b'c  &quot;&quot; $(var d)$(var d)"/>
        </launch>
        """,
    )
    (spec,) = plan.processes()
    assert spec.argv == ("echo", "/opt/x/bin", "a/opt/x bc", "", "/opt/x/opt/x")


def test_environment_tags(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <set_env name="A" value="1"/>
          <append_env name="P" value="x"/>
          <append_env name="P" value="y" separator=";"/>
          <append_env name="P" value="w" prepend="true"/>
          <unset_env name="KEEP"/>
          <executable cmd="true"/>
          <reset_env/>
          <executable cmd="true"/>
        </launch>
        """,
    )
    before, after = plan.processes()
    assert before.env_changes["A"] == "1" and before.env_changes["P"] == "w:x;y"
    assert before.env_changes["KEEP"] is None
    assert "A" not in after.env_changes and "KEEP" not in after.env_changes


def test_timer_shutdown_and_reset(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <let name="a" value="1"/>
          <let name="b" value="2"/>
          <reset><keep name="a" value="$(var a)"/></reset>
          <log message="$(var a) $(var b none)"/>
          <timer period="2.5" cancel_on_shutdown="false">
            <log message="later"/>
          </timer>
          <shutdown reason="done here"/>
          <shutdown/>
        </launch>
        """,
    )
    assert logs(plan) == ["1 none"]
    timer = next(s for s in plan.steps if isinstance(s, StartTimer))
    assert timer.period == 2.5 and not timer.cancel_on_shutdown
    assert timer.body is not None and isinstance(timer.body.entities[0], actions.LogInfo)
    reasons = [s.reason for s in plan.steps if isinstance(s, RequestShutdown)]
    assert reasons == ["done here", "reason not given"]


def test_if_and_unless_on_actions(tmp_path: Path) -> None:
    body = """
        <launch>
          <arg name="on" default="true"/>
          <log message="if" if="$(var on)"/>
          <log message="unless" unless="$(var on)"/>
          <group if="$(not $(var on))"><log message="group"/></group>
          <executable cmd="true" unless="true"/>
          <timer period="1" if="false"><log message="never"/></timer>
          <let name="x" value="1" if="1"/>
          <set_env name="E" value="1" if="0"/>
        </launch>
    """
    plan = plan_of(tmp_path, body)
    assert logs(plan) == ["if"] and not plan.processes()
    assert logs(plan_of(tmp_path, body, on="false")) == ["unless", "group"]
    ld = load(tmp_path, body)
    assert isinstance(ld.entities[1].condition, IfCondition)
    assert isinstance(ld.entities[2].condition, UnlessCondition)


def test_origins_are_the_tag_lines(tmp_path: Path) -> None:
    ld = load(
        tmp_path,
        """
        <launch>

          <log
             message="x"/>
          <group>
            <executable cmd="true"/>
          </group>
        </launch>
        """,
    )
    log, group = ld.entities
    assert log.origin == f"{tmp_path}/t.launch.xml:3"
    assert group.actions[0].origin == f"{tmp_path}/t.launch.xml:6"
    assert ld.origin == f"{tmp_path}/t.launch.xml:1"


# --- typing of attributes --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "value"), [("true", True), ("1", True), ("No", False), ("0", False)]
)
def test_bool_attributes_take_yaml_style_words(tmp_path: Path, text: str, value: bool) -> None:
    (process,) = load(
        tmp_path, f'<launch><executable cmd="true" shell="{text}"/></launch>'
    ).entities
    assert process.shell is value


def test_typed_attributes_with_substitutions_are_performed_later(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        <launch>
          <arg name="t" default="3"/>
          <arg name="r" default="false"/>
          <executable cmd="true" sigterm_timeout="$(var t)" respawn="$(var r)"
                      emulate_tty="$(var r)"/>
          <timer period="$(var t)"><log message="x"/></timer>
        </launch>
        """,
        r="true",
    )
    (spec,) = plan.processes()
    assert spec.sigterm_timeout == 3.0 and spec.respawn.mode == "always"
    assert next(s for s in plan.steps if isinstance(s, StartTimer)).period == 3.0


@pytest.mark.parametrize(
    ("attrs", "message"),
    [
        ('shell="maybe"', "attribute 'shell' is 'maybe', expected a boolean"),
        ('shell="$(var s)"', "'shell' cannot hold substitutions"),
        ('sigterm_timeout="soon"', "attribute 'sigterm_timeout' is 'soon', expected a number"),
        ('respawn_delay="-1"', "attribute 'respawn_delay' is -1.0, must be >= 0"),
        ('respawn_max_retries="2.5"', "'respawn_max_retries' is '2.5', expected an integer"),
        ('output="loud"', "output='loud' is not an output mode; valid: log, screen, both"),
        ('respawn="sometimes"', "respawn='sometimes' is not valid; valid: true, false, always"),
        ('on_exit="restart"', "on_exit='restart' is not supported; the only value is 'shutdown'"),
        ('if="yes"', "if='yes' is not a condition value; valid: true, false, 1, 0"),
        ('if="1" unless="0"', "'if' and 'unless' cannot both be given"),
    ],
)
def test_attribute_value_errors(tmp_path: Path, attrs: str, message: str) -> None:
    err = error(tmp_path, f'<launch>\n  <executable cmd="true" {attrs}/>\n</launch>\n')
    assert message in err.message
    assert err.what == "<executable>"
    assert err.where is not None and err.where.startswith(f"{tmp_path}/t.launch.xml:2:")


# --- strictness: errors with file:line:col ---------------------------------------------------


def test_unknown_attribute_names_the_valid_ones(tmp_path: Path) -> None:
    err = error(tmp_path, '<launch>\n  <executable cmd="true" nmae="x"/>\n</launch>\n')
    assert err.where == f"{tmp_path}/t.launch.xml:2:32"
    assert err.what == "<executable>"
    assert err.message.startswith("unknown attribute 'nmae' (did you mean 'name'?)")
    assert "valid attributes: name, cwd, launch-prefix, output, shell" in err.message
    assert str(err).startswith(f"{tmp_path}/t.launch.xml:2:32: <executable>: unknown attribute")


def test_unknown_tag_with_did_you_mean(tmp_path: Path) -> None:
    err = error(tmp_path, '<launch>\n  <group>\n    <exectuable cmd="x"/>\n  </group>\n</launch>')
    assert err.where == f"{tmp_path}/t.launch.xml:3:5"
    assert "unknown tag 'exectuable' (did you mean 'executable'?)" in err.message
    assert "valid tags: append_env, arg, executable" in err.message


@pytest.mark.parametrize(
    ("body", "where", "message"),
    [
        ("<launch>\n<log/>\n</launch>", "2:1", "missing required attribute 'message'"),
        ('<launch>\n<log mesage="x"/>\n</launch>', "2:1", "'message' (found 'mesage': a typo?)"),
        ("<launch>\n<param name='a' value='1'/>\n</launch>", "2:1", "use set_parameter"),
        ("<launch>\n<ros_timer/>\n</launch>", "2:1", "not supported by mlaunch"),
        ("<launch>\n<node_container/>\n</launch>", "2:1", "missing required attribute 'exec'"),
        ("<launch>\n<rosparam/>\n</launch>", "2:1", "that is ROS 1"),
        ("<ros>\n</ros>", "1:1", "the root must be 'launch', not 'ros'"),
        ("<launch>\n<log message='x'>hello</log>\n</launch>", "2:18", "unexpected text 'hello'"),
        ("<launch>\n<log message='x'/>\n", "3:1", "malformed XML: no element found"),
        ("<launch>\n<log message='x' message='y'/>\n</launch>", "2:18", "duplicate attribute"),
        ("<launch>\n  <log message='x'>\n</launch>", "3:3", "malformed XML: mismatched tag"),
        (
            "<launch>\n<executable cmd='true'>\n  <remap from='a' to='b'/>\n</executable>\n</launch>",
            "3:3",
            "unexpected tag <remap>; valid children: <env>",
        ),
        (
            "<launch>\n<executable cmd='true'>\n  <env name='A'/>\n</executable>\n</launch>",
            "3:3",
            "missing required attribute 'value'",
        ),
        (
            '<launch>\n<executable cmd="echo \'open"/>\n</launch>',
            "2:18",
            "attribute 'cmd': the quote ' is not closed",
        ),
        ("<launch>\n<arg name='$(var x)'/>\n</launch>", "2:12", "must be plain text"),
        ("<launch>\n<executable cmd='  '/>\n</launch>", "2:18", "attribute 'cmd' is empty"),
        ("<launch>\n<timer><log message='x'/></timer>\n</launch>", "2:1", "'period'"),
        ("<launch>\n<include file='x.py'><arg name='a'/></include>\n</launch>", "2:22", "'value'"),
    ],
)
def test_errors_are_located(tmp_path: Path, body: str, where: str, message: str) -> None:
    err = error(tmp_path, body)
    assert message in err.message, err.message
    assert err.where == f"{tmp_path}/t.launch.xml:{where}"
    assert "\n" not in str(err)


def test_included_file_errors_name_the_included_file(tmp_path: Path) -> None:
    write(tmp_path, "<launch>\n  <lgo message='x'/>\n</launch>\n", "bad.launch.xml")
    path = write(tmp_path, '<launch><include file="$(dirname)/bad.launch.xml"/></launch>')
    with pytest.raises(MlaunchError) as caught:
        resolve(readers.load(str(path)), path=str(path), arguments={}, environ=ENV, options=None)
    assert caught.value.where == f"{tmp_path}/bad.launch.xml:2:3"
    assert "did you mean 'log'?" in str(caught.value)


def test_schema_attributes_on_the_root_are_ignored(tmp_path: Path) -> None:
    ld = load(
        tmp_path,
        """
        <launch xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
                xsi:noNamespaceSchemaLocation="launch.xsd" deprecated="use other.launch.xml">
          <log message="x"/>
        </launch>
        """,
    )
    assert ld.deprecated_reason == "use other.launch.xml"


# --- launch_ros tags -------------------------------------------------------------------------


@pytest.fixture
def ros_plan(tmp_path: Path) -> object:
    """Resolve XML text against a fake install prefix holding package 'demo' (talker, listener)."""
    prefix = tmp_path / "prefix"
    (prefix / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (prefix / "share" / "ament_index" / "resource_index" / "packages" / "demo").touch()
    (prefix / "share" / "demo").mkdir()
    (prefix / "share" / "demo" / "params.yaml").write_text("/**:\n  ros__parameters: {a: 1}\n")
    lib = prefix / "lib" / "demo"
    lib.mkdir(parents=True)
    for exe in ("talker", "listener"):
        (lib / exe).write_text("#!/bin/sh\n")
        (lib / exe).chmod(0o755)
    temp = tmp_path / "run"
    temp.mkdir()

    def run(body: str, **args: str) -> Plan:
        path = write(tmp_path, body)
        env = {**ENV, "AMENT_PREFIX_PATH": str(prefix)}
        options = ResolveOptions(temp_dir=str(temp), standins=False)
        return resolve(
            readers.load(str(path)), path=str(path), arguments=args, environ=env, options=options
        )

    run.prefix = prefix  # type: ignore[attr-defined]
    return run


def params_of(argv: tuple[str, ...]) -> list[str]:
    """The content of each --params-file, in order."""
    return [Path(argv[i + 1]).read_text() for i, a in enumerate(argv) if a == "--params-file"]


def test_node_command_line_and_children(ros_plan: Any) -> None:
    plan = ros_plan(
        """
        <launch>
          <arg name="ns" default="r1"/>
          <push-ros-namespace namespace="$(var ns)"/>
          <node pkg="demo" exec="talker" name="talker" namespace="sub" exec_name="speaker"
                args="--count 3 'two words'" ros_args="--log-level debug" output="screen"
                respawn="true" respawn_delay="1" sigterm_timeout="2">
            <param name="rate" value="10.5"/>
            <param from="$(find-pkg-share demo)/params.yaml"/>
            <remap from="chatter" to="chat"/>
            <env name="MODE" value="x"/>
          </node>
        </launch>
        """
    )
    (spec,) = plan.processes()
    exe = str(ros_plan.prefix / "lib" / "demo" / "talker")
    share = ros_plan.prefix / "share" / "demo"
    assert spec.argv[:4] == (exe, "--count", "3", "two words")
    assert spec.argv[4:7] == ("--ros-args", "--log-level", "debug")
    assert spec.argv[7:12] == ("--ros-args", "-r", "__node:=talker", "-r", "__ns:=/r1/sub")
    assert spec.argv[-4:] == ("--params-file", f"{share}/params.yaml", "-r", "chatter:=chat")
    assert params_of(spec.argv)[0] == "/r1/sub/talker:\n  ros__parameters:\n    rate: 10.5\n"
    assert spec.label == "speaker-1" and spec.output == "screen"
    assert spec.respawn.delay == 1.0 and spec.sigterm_timeout == 2.0
    assert spec.env_changes["MODE"] == "x"
    assert spec.node is not None and spec.node.fully_qualified_name == "/r1/sub/talker"


def test_global_ros_tags_both_namespace_spellings_and_scopes(ros_plan: Any) -> None:
    plan = ros_plan(
        """
        <launch>
          <group>
            <push_ros_namespace namespace="a"/>
            <push-ros-namespace namespace="b"/>
            <set_parameter name="use_sim_time" value="true"/>
            <set_parameter name="level" value="3"/>
            <set_parameters_from_file filename="$(find-pkg-share demo)/params.yaml"/>
            <set_remap from="/tf" to="tf"/>
            <node pkg="demo" exec="listener"/>
          </group>
          <node pkg="demo" exec="listener" name="plain"/>
        </launch>
        """
    )
    inner, outer = plan.processes()
    share = ros_plan.prefix / "share" / "demo"
    assert inner.argv[1:] == (
        "--ros-args", "-r", "__ns:=/a/b", "-p", "use_sim_time:=True", "-p", "level:=3",
        "--params-file", f"{share}/params.yaml", "-r", "/tf:=tf",
    )  # fmt: skip
    assert outer.argv[1:] == ("--ros-args", "-r", "__node:=plain")


def test_lifecycle_node_needs_name_and_namespace(ros_plan: Any, tmp_path: Path) -> None:
    plan = ros_plan(
        '<launch><lifecycle_node pkg="demo" exec="talker" name="lc" namespace="/"'
        ' autostart="true"/></launch>'
    )
    (spec,) = plan.processes()
    assert spec.node is not None and spec.node.lifecycle and spec.node.autostart
    err = error(
        tmp_path, '<launch>\n<lifecycle_node pkg="demo" exec="talker" name="lc"/>\n</launch>'
    )
    assert err.where == f"{tmp_path}/t.launch.xml:2:1"
    assert "missing required attribute 'namespace'" in err.message


@pytest.mark.parametrize(
    ("param", "content"),
    [
        ('name="p" value="7"', "p: 7"),
        ('name="p" value="7.0"', "p: 7.0"),
        ('name="p" value="True"', "p: true"),
        ('name="p" value="text"', "p: text"),
        ('name="p" value="[1, 2]"', "p:\n    - 1\n    - 2"),
        ('name="p" value="7" type="str"', "p: '7'"),
        ('name="p" value="true" type="str"', "p: 'true'"),
        ('name="p" value="3" type="float"', "p: 3.0"),
        ('name="p" value="yes" type="bool"', "p: true"),
        ('name="p" value="0" type="bool"', "p: false"),
        ('name="p" value="[1, 2]" type="list_of_float"', "p:\n    - 1.0\n    - 2.0"),
        ('name="p" value="1;2" value-sep=";" type="list_of_int"', "p:\n    - 1\n    - 2"),
        ('name="p" value="a,b" value-sep=","', "p:\n    - a\n    - b"),
        ('name="p" value="1,2" value-sep="," type="list_of_str"', "p:\n    - '1'\n    - '2'"),
        ('name="p" value="$(var x)"', "p: 42"),
        ('name="p" value="$(var x)" type="str"', "p: '42'"),
        ('name="p" value="$(var x),1" value-sep=","', "p:\n    - 42\n    - 1"),
        ('name="p" value="{a: 1}" type="yaml"', "p: '{a: 1}'"),
    ],
)
def test_param_typing(ros_plan: Any, param: str, content: str) -> None:
    plan = ros_plan(
        f'<launch><node pkg="demo" exec="talker"><param {param}/></node></launch>', x="42"
    )
    (spec,) = plan.processes()
    assert params_of(spec.argv) == [f"/**:\n  ros__parameters:\n    {content}\n"]


def test_nested_params_are_dotted_names(ros_plan: Any) -> None:
    plan = ros_plan(
        """
        <launch>
          <node pkg="demo" exec="talker">
            <param name="arm">
              <param name="joints" value="[j1, j2]"/>
              <param name="limits"><param name="speed" value="0.5"/></param>
            </param>
            <param name="b" value="1"/>
          </node>
        </launch>
        """
    )
    (spec,) = plan.processes()
    assert params_of(spec.argv) == [
        "/**:\n  ros__parameters:\n    arm.joints:\n    - j1\n    - j2\n    arm.limits.speed: 0.5\n",
        "/**:\n  ros__parameters:\n    b: 1\n",
    ]


def test_param_from_file_with_allow_substs(ros_plan: Any, tmp_path: Path) -> None:
    source = tmp_path / "subst.yaml"
    source.write_text("/**:\n  ros__parameters:\n    robot: $(var robot)\n")
    plan = ros_plan(
        f'<launch><node pkg="demo" exec="talker"><param from="{source}" allow_substs="true"/>'
        "</node></launch>",
        robot="r9",
    )
    (spec,) = plan.processes()
    assert params_of(spec.argv) == ["/**:\n  ros__parameters:\n    robot: r9\n"]


@pytest.mark.parametrize(
    ("param", "message"),
    [
        ('name="p" value="x" type="integer"', "type='integer' is not a parameter type; valid: str"),
        ('name="p" value="abc" type="int"', "parameter value 'abc' is not of type int"),
        ('name="p" value="2.5" type="int"', "parameter value '2.5' is not of type int"),
        ('name="p" value="maybe" type="bool"', "parameter value 'maybe' is not of type bool"),
        ('name="p" value="1" type="list_of_int"', "is not a list; write [a, b] or split it"),
        ('name="p" value="1,a" value-sep=","', "must hold one type, this one mixes int, str"),
        ('name="p" value="1" value-sep=""', "value-sep is empty"),
        ('name="p"', "param 'p' needs 'value' (or nested params)"),
        ('value="1"', "a param needs 'name'"),
        ('name="p" from="x.yaml"', "'from' and 'name' cannot both be given"),
        ('name="p" value="1" allow_substs="true"', "'allow_substs' is only valid with 'from'"),
        ('name="p" value="1" vlaue="2"', "unknown attribute 'vlaue' (did you mean 'value'?)"),
    ],
)
def test_param_errors(tmp_path: Path, param: str, message: str) -> None:
    err = error(
        tmp_path,
        f'<launch>\n<node pkg="demo" exec="talker">\n  <param {param}/>\n</node>\n</launch>',
    )
    assert message in err.message
    assert err.where is not None and err.where.startswith(f"{tmp_path}/t.launch.xml:3:")
    assert err.what == "<param>"


def test_nested_param_errors(tmp_path: Path) -> None:
    err = error(
        tmp_path,
        '<launch>\n<node pkg="demo" exec="talker">\n  <param name="a" value="1">\n'
        '    <param name="b" value="2"/>\n  </param>\n</node>\n</launch>',
    )
    assert "a param with nested params cannot have 'value'" in err.message
    assert err.where is not None and err.where.startswith(f"{tmp_path}/t.launch.xml:3:")


@pytest.mark.parametrize(
    ("tag", "message"),
    [
        ('<node exec="talker" cmd="x"/>', "unknown attribute 'cmd'"),
        ('<node pkg="demo"/>', "missing required attribute 'exec'"),
        ('<node pkg="demo" exe="talker"/>', "missing required attribute 'exec' (found 'exe'"),
        ('<node exec="x"><choice value="a"/></node>', "valid children: <env>, <param>, <remap>"),
        ('<set_remap from="a"/>', "missing required attribute 'to'"),
        ('<set_parameters_from_file file="x"/>', "missing required attribute 'filename'"),
        ('<push_ros_namespace ns="x"/>', "missing required attribute 'namespace'"),
        ('<node exec="x"><remap from="a" to="b" if="1"/></node>', "unknown attribute 'if'"),
    ],
)
def test_ros_tag_errors(tmp_path: Path, tag: str, message: str) -> None:
    err = error(tmp_path, f"<launch>\n  {tag}\n</launch>")
    assert message in err.message
    assert err.where is not None and err.where.startswith(f"{tmp_path}/t.launch.xml:2:")


def test_set_use_sim_time_and_set_ros_log_dir(ros_plan: Any) -> None:
    plan = ros_plan(
        """
        <launch>
          <set_use_sim_time value="true"/>
          <set_ros_log_dir new_log_dir="/var/log/robot"/>
          <node pkg="demo" exec="talker"/>
        </launch>
        """
    )
    (spec,) = plan.processes()
    assert spec.env_changes["ROS_LOG_DIR"] == "/var/log/robot"
    # As in Jazzy, set_use_sim_time does not reach the nodes; mlaunch says so.
    assert spec.argv[1:] == ("--ros-args",)
    assert any("SetUseSimTime(True)" in w for w in plan.warnings)
