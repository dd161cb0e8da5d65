"""Pure tests of the ROS layer: the exact Node command line, params files, scope, errors.

Packages are fake ament prefixes built in tmp_path (executables are tiny shell scripts), so no
ROS installation is needed; nothing here starts a process.
"""

from __future__ import annotations

import os
import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from mlaunch import standins
from mlaunch.launch.actions import GroupAction, LaunchDescription
from mlaunch.launch.substitutions import LaunchConfiguration, TextSubstitution, perform
from mlaunch.launch_ros.actions import (
    LifecycleNode,
    Node,
    PushRosNamespace,
    SetParameter,
    SetParametersFromFile,
    SetRemap,
    SetROSLogDir,
    SetUseSimTime,
    prefix_namespace,
    with_use_sim_time,
)
from mlaunch.launch_ros.events import (
    ChangeState,
    OnStateTransition,
    StateTransition,
    matches_node_name,
)
from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile, ParameterValue
from mlaunch.launch_ros.substitutions import FindPackageShare
from mlaunch.launch_ros.substitutions import Parameter as ParameterSubstitution
from mlaunch.plan.errors import (
    LaunchFileError,
    MlaunchError,
    PackageNotFoundError,
    SubstitutionFailure,
)
from mlaunch.plan.steps import Plan, ProcessSpec
from mlaunch.resolve.resolver import ResolveOptions, resolve
from mlaunch.ros import packages
from mlaunch.ros.search import PackageSearch

THIS = os.path.abspath(__file__)


@pytest.fixture(autouse=True)
def _fresh_packages() -> Iterator[None]:
    packages.forget_scans()
    yield
    packages.forget_scans()


def make_prefix(root: Path, contents: dict[str, list[str]]) -> Path:
    """A fake ament prefix: each package in the index, with executable scripts in lib/<pkg>."""
    index = root / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True, exist_ok=True)
    for package, executables in contents.items():
        (index / package).write_text("")
        (root / "share" / package).mkdir(parents=True, exist_ok=True)
        libexec = root / "lib" / package
        libexec.mkdir(parents=True, exist_ok=True)
        for exe in executables:
            path = libexec / exe
            path.write_text("#!/bin/sh\nexit 0\n")
            path.chmod(0o755)
    return root


@pytest.fixture
def prefix(tmp_path: Path) -> Path:
    return make_prefix(
        tmp_path / "install",
        {"demo": ["talker", "listener"], "tools": ["helper"]},
    )


@pytest.fixture
def temp_dir(tmp_path: Path) -> str:
    path = tmp_path / "run"
    path.mkdir()
    return str(path)


def run(
    entities: list[Any],
    prefix: Path,
    temp_dir: str | None,
    *,
    args: dict[str, str] | None = None,
    **options: Any,
) -> Plan:
    environ = {"PATH": os.environ["PATH"], "HOME": "/home/u", "AMENT_PREFIX_PATH": str(prefix)}
    return resolve(
        LaunchDescription(entities),
        path=None,
        arguments=args or {},
        environ=environ,
        options=ResolveOptions(temp_dir=temp_dir, **options),
    )


def only(plan: Plan) -> ProcessSpec:
    (spec,) = plan.processes()
    return spec


def ros_part(spec: ProcessSpec) -> list[str]:
    """argv from the last --ros-args on, with params-file paths replaced by their YAML."""
    argv = list(spec.argv)
    start = len(argv) - 1 - argv[::-1].index("--ros-args")
    out = []
    for i, item in enumerate(argv[start:], start):
        if argv[i - 1] == "--params-file" and os.path.basename(item).startswith("launch_params_"):
            out.append("FILE:" + Path(item).read_text())
        else:
            out.append(item)
    return out


def params_of(spec: ProcessSpec) -> list[dict[str, Any]]:
    """The YAML documents of the params files mlaunch wrote for a process, in argv order."""
    return [yaml.safe_load(a[5:]) for a in ros_part(spec) if a.startswith("FILE:")]


def talker(prefix: Path) -> str:
    return str(prefix / "lib" / "demo" / "talker")


# --- the command line ------------------------------------------------------------------------


def test_bare_node_is_the_executable_and_one_ros_args(prefix: Path, temp_dir: str) -> None:
    spec = only(run([Node(package="demo", executable="talker")], prefix, temp_dir))
    assert spec.argv == (talker(prefix), "--ros-args")
    assert spec.label == "talker-1"
    assert spec.node is not None
    assert (spec.node.name, spec.node.namespace, spec.node.package) == (None, "/", "demo")
    assert spec.node.fully_qualified_name is None
    assert spec.standin is None


def test_full_order_of_a_node_command_line(prefix: Path, temp_dir: str) -> None:
    params_file = Path(temp_dir) / "given.yaml"
    params_file.write_text("/**:\n  ros__parameters:\n    g: 1\n")
    global_file = Path(temp_dir) / "global.yaml"
    global_file.write_text("/**:\n  ros__parameters:\n    h: 2\n")
    node = Node(
        package="demo",
        executable="talker",
        name="talker",
        namespace="ns",
        arguments=["--foo", ["a", LaunchConfiguration("x")]],
        ros_arguments=["--log-level", "debug"],
        parameters=[{"a": 1}, str(params_file), Parameter("p", 5)],
        remappings=[("chatter", ["chat_", LaunchConfiguration("x")])],
    )
    entities = [
        SetParameter("use_sim_time", True),
        SetParametersFromFile(str(global_file)),
        SetParameter("rate", 2.5),
        SetRemap("tf", "/tf_global"),
        node,
    ]
    spec = only(run(entities, prefix, temp_dir, args={"x": "X"}))
    argv = list(spec.argv)
    (written,) = [a for a in argv if os.path.basename(a).startswith("launch_params_")]
    assert argv == [
        talker(prefix),
        "--foo",
        "aX",
        "--ros-args",
        "--log-level",
        "debug",
        "--ros-args",
        "-r",
        "__node:=talker",
        "-r",
        "__ns:=/ns",
        "-p",
        "use_sim_time:=True",
        "--params-file",
        str(global_file),
        "-p",
        "rate:=2.5",
        "--params-file",
        written,
        "--params-file",
        str(params_file),
        "-p",
        "p:=5\n...\n",
        "-r",
        "tf:=/tf_global",
        "-r",
        "chatter:=chat_X",
    ]
    assert os.path.dirname(written) == temp_dir
    assert os.path.basename(written).startswith("launch_params_")
    assert Path(written).read_text() == "/ns/talker:\n  ros__parameters:\n    a: 1\n"


def test_pathlib_paths_as_parameters(prefix: Path, temp_dir: str) -> None:
    """A pathlib.Path is a params file, a parameter's value and a name part, as in launch_ros
    (found without mlaunch importing pathlib itself: the launch file made the Path)."""
    given = Path(temp_dir) / "given.yaml"
    given.write_text("/**:\n  ros__parameters:\n    g: 1\n")
    node = Node(
        package="demo",
        executable="talker",
        name="talker",
        parameters=[{"where": Path("/a/b")}, given, Parameter(Path("p"), Path("/c"))],
    )
    spec = only(run([node], prefix, temp_dir))
    files = [spec.argv[i + 1] for i, word in enumerate(spec.argv) if word == "--params-file"]
    assert files[1] == str(given)
    assert Path(files[0]).read_text() == "/**:\n  ros__parameters:\n    where: /a/b\n"
    assert [w for w in spec.argv if w.startswith("p:=")] == ["p:=/c\n...\n"]  # as p:=5 is


@pytest.mark.parametrize(
    ("pushed", "namespace", "expected"),
    [
        ([], None, None),
        ([], "", "/"),
        ([], "a", "/a"),
        ([], "/a/b/", "/a/b"),
        (["r1"], None, "/r1"),
        (["r1"], "", "/r1"),
        (["r1"], "ns", "/r1/ns"),
        (["r1"], "/abs", "/abs"),
        (["r1", "r2"], "ns", "/r1/r2/ns"),
        (["r1", "/top"], "ns", "/top/ns"),
        (["/"], "ns", "/ns"),
        (["r1/"], "a/b", "/r1/a/b"),
        (["/r1", ""], None, "/r1"),
    ],
)
def test_namespace_joins_like_launch_ros(
    prefix: Path, temp_dir: str, pushed: list[str], namespace: str | None, expected: str | None
) -> None:
    entities: list[Any] = [PushRosNamespace(ns) for ns in pushed]
    entities.append(Node(package="demo", executable="talker", name="t", namespace=namespace))
    spec = only(run(entities, prefix, temp_dir))
    ros = ros_part(spec)
    if expected is None:
        assert ros == ["--ros-args", "-r", "__node:=t"]
        assert spec.node is not None and spec.node.namespace == "/"
    else:
        assert ros == ["--ros-args", "-r", "__node:=t", "-r", f"__ns:={expected}"]
        assert spec.node is not None and spec.node.namespace == expected
        assert spec.node.fully_qualified_name == prefix_namespace(expected, "t")


def test_prefix_namespace_rules() -> None:
    assert prefix_namespace(None, None) is None
    assert prefix_namespace("my_ns", "original_ns") == "/my_ns/original_ns"
    assert prefix_namespace("/my_ns", "/original_ns") == "/original_ns"
    assert prefix_namespace(None, "original_ns") == "/original_ns"
    assert prefix_namespace("my_ns", None) == "/my_ns"
    assert prefix_namespace("/", "/") == "/"
    assert prefix_namespace("", "x") == "/x"


def test_params_file_key_is_full_name_only_when_name_and_namespace_known(
    prefix: Path, temp_dir: str
) -> None:
    cases = [
        Node(package="demo", executable="talker", parameters=[{"a": 1}]),
        Node(package="demo", executable="talker", name="n", parameters=[{"a": 1}]),
        Node(package="demo", executable="talker", namespace="ns", parameters=[{"a": 1}]),
        Node(package="demo", executable="talker", name="n", namespace="ns", parameters=[{"a": 1}]),
        GroupAction(
            [
                PushRosNamespace("robot"),
                Node(package="demo", executable="talker", name="n", parameters=[{"a": 1}]),
            ]
        ),
    ]
    plan = run(cases, prefix, temp_dir)
    keys = [next(iter(params_of(spec)[0])) for spec in plan.processes()]
    assert keys == ["/**", "/**", "/**", "/ns/n", "/robot/n"]


def test_one_params_file_per_dict_with_flattened_sorted_keys(prefix: Path, temp_dir: str) -> None:
    node = Node(
        package="demo",
        executable="talker",
        parameters=[
            {"zeta": 1, "nested": {"deeper": {"x": 1.5}, "flag": True}, "alpha": "text"},
            {"second": [1, 2, 3]},
        ],
    )
    spec = only(run([node], prefix, temp_dir))
    files = [a for a in ros_part(spec) if a.startswith("FILE:")]
    assert len(files) == 2
    assert files[0][5:] == textwrap.dedent(
        """\
        /**:
          ros__parameters:
            alpha: text
            nested.deeper.x: 1.5
            nested.flag: true
            zeta: 1
        """
    )
    assert files[1][5:] == textwrap.dedent(
        """\
        /**:
          ros__parameters:
            second:
            - 1
            - 2
            - 3
        """
    )


def test_dict_value_typing_follows_launch_ros(prefix: Path, temp_dir: str) -> None:
    lc = LaunchConfiguration
    node = Node(
        package="demo",
        executable="talker",
        parameters=[
            {
                "plain_true_text": "true",  # a plain str stays a str
                "subst_true": lc("yes"),  # a substitution is read with YAML
                "subst_float": lc("one"),
                "subst_empty": lc("empty"),
                "subst_list": lc("list"),
                "subst_text": lc("word"),
                "ints": [1, 2],
                "mixed_numbers": [1, 2.5],
                "bools": [True, False],
                "strings": ["a", "b"],
                "concatenated": ["prefix_", lc("word"), "_suffix"],
                "forced_text": ParameterValue(lc("one"), value_type=str),
                "forced_int": ParameterValue(lc("seven"), value_type=int),
                "forced_floats": ParameterValue(lc("list"), value_type=list[float]),
                "bytes": b"\x01",
            }
        ],
    )
    args = {"yes": "true", "one": "1.0", "empty": "", "list": "[1, 2]", "word": "w", "seven": "7"}
    spec = only(run([node], prefix, temp_dir, args=args))
    (document,) = params_of(spec)
    values = document["/**"]["ros__parameters"]
    assert values == {
        "plain_true_text": "true",
        "subst_true": True,
        "subst_float": 1.0,
        "subst_empty": "",
        "subst_list": [1, 2],
        "subst_text": "w",
        "ints": [1, 2],
        "mixed_numbers": [1.0, 2.5],
        "bools": [True, False],
        "strings": ["a", "b"],
        "concatenated": "prefix_w_suffix",
        "forced_text": "1.0",
        "forced_int": 7,
        "forced_floats": [1.0, 2.0],
        "bytes": b"\x01",
    }


def test_each_item_its_own_list_is_read_with_yaml_and_must_be_uniform(
    prefix: Path, temp_dir: str
) -> None:
    lc = LaunchConfiguration
    good = Node(
        package="demo",
        executable="talker",
        parameters=[{"names": [[lc("a")], [lc("b")], "c"]}],
    )
    spec = only(run([good], prefix, temp_dir, args={"a": "x", "b": "y"}))
    assert params_of(spec)[0]["/**"]["ros__parameters"]["names"] == ["x", "y", "c"]
    bad = Node(package="demo", executable="talker", parameters=[{"mixed": [[lc("a")], "c"]}])
    with pytest.raises(SubstitutionFailure, match=r"parameter 'mixed' is the list \[1, 'c'\]"):
        run([bad], prefix, temp_dir, args={"a": "1"})


def test_robot_description_text_stays_a_string(prefix: Path, temp_dir: str) -> None:
    urdf = '<?xml version="1.0"?>\n<robot name="r">\n  <link name="base: 1"/>\n</robot>\n'
    node = Node(
        package="demo",
        executable="talker",
        parameters=[
            {"robot_description": ParameterValue(LaunchConfiguration("u"), value_type=str)}
        ],
    )
    spec = only(run([node], prefix, temp_dir, args={"u": urdf}))
    assert params_of(spec)[0]["/**"]["ros__parameters"]["robot_description"] == urdf
    # Without value_type=str the same text is read as YAML, which fails as in ROS 2.
    raw = Node(
        package="demo",
        executable="talker",
        parameters=[{"robot_description": LaunchConfiguration("u")}],
    )
    with pytest.raises(SubstitutionFailure, match="value_type=str"):
        run([raw], prefix, temp_dir, args={"u": urdf})


@pytest.mark.parametrize(
    ("value", "args", "message"),
    [
        ([1, "a"], {}, r"parameter 'bad' is the list \[1, 'a'\] of int, str"),
        ([], {}, r"parameter 'bad' is the list \[\] of nothing"),
        (LaunchConfiguration("m"), {"m": "{a: 1}"}, r"YAML reads as dict.*value_type=str"),
        (LaunchConfiguration("m"), {"m": "[1, a]"}, r"parameter 'bad' is the list \[1, 'a'\]"),
        (LaunchConfiguration("m"), {"m": "a: b: c"}, r"Unable to parse 'a: b: c' as YAML"),
        (LaunchConfiguration("m"), {"m": "null"}, r"YAML reads as NoneType"),
    ],
)
def test_bad_parameter_values_name_the_parameter(
    prefix: Path, temp_dir: str, value: Any, args: dict[str, str], message: str
) -> None:
    node = Node(package="demo", executable="talker", parameters=[{"bad": value}])
    with pytest.raises(SubstitutionFailure, match=message) as err:
        run([node], prefix, temp_dir, args=args)
    assert err.value.where == f"{THIS}:{_line_of(node)}"
    assert err.value.what is not None and "Node(package='demo'" in err.value.what


def _line_of(action: Any) -> str:
    return action.origin.rsplit(":", 1)[1]


def test_parameters_must_be_a_list(prefix: Path) -> None:
    with pytest.raises(LaunchFileError, match="parameters must be a list"):
        Node(package="demo", executable="talker", parameters={"a": 1})
    with pytest.raises(LaunchFileError, match="arguments must be a list"):
        Node(package="demo", executable="talker", arguments="--foo --bar")
    with pytest.raises(LaunchFileError, match=r"remapping must be a \(from, to\) pair"):
        Node(package="demo", executable="talker", remappings=[("a", "b", "c")])
    with pytest.raises(LaunchFileError, match="not of type int"):
        ParameterValue("x", value_type=int)


def test_parameter_rule_is_yaml_dumped(prefix: Path, temp_dir: str) -> None:
    node = Node(
        package="demo",
        executable="talker",
        parameters=[
            Parameter("flag", True),
            Parameter("rate", LaunchConfiguration("r")),
            Parameter("names", ["a", "b"]),
            Parameter("text", LaunchConfiguration("r"), value_type=str),
        ],
    )
    spec = only(run([node], prefix, temp_dir, args={"r": "2.5"}))
    assert ros_part(spec)[1:] == [
        "-p",
        "flag:=true\n...\n",
        "-p",
        "rate:=2.5\n...\n",
        "-p",
        "names:=- a\n- b\n",
        "-p",
        "text:='2.5'\n",
    ]


def test_global_parameter_values_use_python_str_and_yaml_lists(prefix: Path, temp_dir: str) -> None:
    entities = [
        SetParameter("flag", True),
        SetParameter("text", "true"),
        SetParameter("subst", LaunchConfiguration("v")),
        SetParameter("numbers", [1, 2.5]),
        SetParameter("names", ["a b", "y"]),
        SetParameter(["na", "me"], "x"),
        Node(package="demo", executable="talker"),
    ]
    spec = only(run(entities, prefix, temp_dir, args={"v": "3"}))
    assert ros_part(spec) == [
        "--ros-args",
        "-p",
        "flag:=True",
        "-p",
        "text:=true",
        "-p",
        "subst:=3",
        "-p",
        "numbers:=[1.0, 2.5]",
        "-p",
        "names:=[a b, 'y']",
        "-p",
        "name:=x",
    ]


def test_parameter_substitution_reads_globals(prefix: Path, temp_dir: str) -> None:
    from mlaunch.launch.actions import LogInfo
    from mlaunch.plan.steps import Log

    entities = [
        SetParameter("speed", 1.5),
        LogInfo(msg=["speed=", ParameterSubstitution("speed")]),
        LogInfo(msg=["other=", ParameterSubstitution("other", default=7)]),
    ]
    plan = run(entities, prefix, temp_dir)
    assert [s.message for s in plan.steps if isinstance(s, Log)] == ["speed=1.5", "other=7"]
    with pytest.raises(SubstitutionFailure, match="parameter 'nope' not found"):
        run([LogInfo(msg=ParameterSubstitution("nope"))], prefix, temp_dir)


# --- scope ---------------------------------------------------------------------------------------


def _scope_entities() -> list[Any]:
    # The outer SetParameter/SetRemap exist first: that is when launch_ros's list.extend leaks.
    return [
        SetParameter("outer", 1),
        SetRemap("a", "b"),
        PushRosNamespace("base"),
        GroupAction(
            [
                SetParameter("inner", 2),
                SetRemap("c", "d"),
                PushRosNamespace("inner_ns"),
                Node(package="demo", executable="talker", name="in"),
            ]
        ),
        Node(package="demo", executable="talker", name="out"),
    ]


INSIDE = ["--ros-args", "-r", "__node:=in", "-r", "__ns:=/base/inner_ns", "-p", "outer:=1"]
INSIDE += ["-p", "inner:=2", "-r", "a:=b", "-r", "c:=d"]


def test_a_scoped_groups_global_parameter_applies_after_it_as_in_launch(
    prefix: Path, temp_dir: str
) -> None:
    """Observed in Jazzy (conformance cases ros_scoping, remap_scope): the parameter and the
    remap leak, the namespace does not; mlaunch says where it happens."""
    plan = run(_scope_entities(), prefix, temp_dir)
    inside, outside = plan.processes()
    assert ros_part(inside) == INSIDE
    assert ros_part(outside) == [
        *["--ros-args", "-r", "__node:=out", "-r", "__ns:=/base"],
        *["-p", "outer:=1", "-p", "inner:=2", "-r", "a:=b", "-r", "c:=d"],
    ]
    parameter, remap = plan.warnings
    assert "this global parameter also applies to the nodes after the enclosing group" in parameter
    assert "this global remap also applies to the nodes after the enclosing group" in remap
    assert "--scoped-parameters" in remap


def test_scoped_parameters_keep_them_inside_the_group(prefix: Path, temp_dir: str) -> None:
    plan = run(_scope_entities(), prefix, temp_dir, scoped_parameters=True)
    inside, outside = plan.processes()
    assert ros_part(inside) == INSIDE
    assert ros_part(outside) == [
        *["--ros-args", "-r", "__node:=out", "-r", "__ns:=/base"],
        *["-p", "outer:=1", "-r", "a:=b"],
    ]
    assert plan.warnings == []


def test_unscoped_group_forwards_ros_state(prefix: Path, temp_dir: str) -> None:
    entities = [
        GroupAction([SetParameter("p", 1), PushRosNamespace("ns")], scoped=False),
        Node(package="demo", executable="talker"),
    ]
    assert ros_part(only(run(entities, prefix, temp_dir))) == [
        "--ros-args",
        "-r",
        "__ns:=/ns",
        "-p",
        "p:=1",
    ]


def test_use_sim_time_option_is_an_action_before_the_description(
    prefix: Path, temp_dir: str
) -> None:
    """--use-sim-time: a SetParameter placed before the file, so it is the first global."""
    description = LaunchDescription(
        [SetParameter("x", 1), Node(package="demo", executable="talker")]
    )
    plan = run([with_use_sim_time(description, True)], prefix, temp_dir)
    assert ros_part(only(plan)) == ["--ros-args", "-p", "use_sim_time:=True", "-p", "x:=1"]
    assert ros_part(only(run([description], prefix, temp_dir))) == ["--ros-args", "-p", "x:=1"]


def test_use_sim_time_argument_is_an_ordinary_launch_argument(prefix: Path, temp_dir: str) -> None:
    """As in ros2 launch: use_sim_time:=true reaches only what the file does with it."""
    node = Node(package="demo", executable="talker")
    plan = run([node], prefix, temp_dir, args={"use_sim_time": "true"})
    assert ros_part(only(plan)) == ["--ros-args"]
    assert any("'use_sim_time' is not declared" in w for w in plan.warnings)


def test_set_use_sim_time_warns_that_nodes_are_not_affected(prefix: Path, temp_dir: str) -> None:
    plan = run([SetUseSimTime(True), Node(package="demo", executable="talker")], prefix, temp_dir)
    assert ros_part(only(plan)) == ["--ros-args"]
    assert any("SetUseSimTime(True) sets use_sim_time only" in w for w in plan.warnings)


def test_set_ros_log_dir_joins_relative_dirs(prefix: Path, temp_dir: str) -> None:
    from mlaunch.launch.actions import ExecuteProcess

    entities = [
        SetROSLogDir("first"),
        ExecuteProcess(cmd=["true"]),
        SetROSLogDir("/abs/logs"),
        ExecuteProcess(cmd=["true"]),
    ]
    first, second = run(entities, prefix, temp_dir).processes()
    assert first.env["ROS_LOG_DIR"] == "/home/u/.ros/log/first"
    assert second.env["ROS_LOG_DIR"] == "/abs/logs"


# --- names, labels, warnings -------------------------------------------------------------------


def test_duplicate_full_names_warn_with_location(prefix: Path, temp_dir: str) -> None:
    first = Node(package="demo", executable="talker", name="t", namespace="r")
    second = Node(package="demo", executable="listener", name="t", namespace="r")
    other = Node(package="demo", executable="listener", name="t", namespace="q")
    plan = run([first, second, other], prefix, temp_dir)
    dup = [w for w in plan.warnings if "nodes with the name" in w]
    assert dup == [
        f"{second.origin}: there are now at least 2 nodes with the name /r/t created within"
        " this launch context"
    ]
    assert second.origin.startswith(THIS + ":")


def test_nodes_without_a_namespace_are_not_counted(prefix: Path, temp_dir: str) -> None:
    """launch_ros counts a node's name only when its namespace is given or pushed."""
    bare = [Node(package="demo", executable="talker", name="t") for _ in range(2)]
    pushed = [
        PushRosNamespace("p"),
        *(Node(package="demo", executable="talker", name="t") for _ in "ab"),
    ]
    plan = run([*bare, GroupAction(pushed)], prefix, temp_dir)
    dup = [w for w in plan.warnings if "nodes with the name" in w]
    assert dup == [
        f"{pushed[2].origin}: there are now at least 2 nodes with the name /p/t created within"
        " this launch context"
    ]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"name": "bad-name"}, r"node name 'bad-name' is invalid: .*alphanumerics or '_'"),
        ({"name": "1st"}, r"node name '1st' is invalid: .*start with a number"),
        ({"name": ""}, r"node name '' is invalid: node name must not be empty"),
        ({"namespace": "a//b"}, r"namespace '/a//b' .*repeated '/'"),
        ({"namespace": "ns-x"}, r"namespace '/ns-x' .*alphanumerics, '_', or '/'"),
        ({"namespace": "a/2b"}, r"namespace '/a/2b' .*token that starts with a number"),
    ],
)
def test_invalid_names_and_namespaces_are_errors_naming_the_value(
    prefix: Path, temp_dir: str, kwargs: dict[str, str], message: str
) -> None:
    node = Node(package="demo", executable="talker", **kwargs)
    with pytest.raises(MlaunchError, match=message) as err:
        run([node], prefix, temp_dir)
    assert err.value.where == node.origin


def test_invalid_pushed_namespace_names_both_parts(prefix: Path, temp_dir: str) -> None:
    with pytest.raises(
        SubstitutionFailure, match=r"previous_namespace='/ok', pushed_namespace='b@d'"
    ):
        run([PushRosNamespace("ok"), PushRosNamespace("b@d")], prefix, temp_dir)


def test_labels_exec_name_and_prefix(prefix: Path, temp_dir: str) -> None:
    entities = [
        Node(package="demo", executable="talker", exec_name="speaker"),
        Node(package="demo", executable="talker", prefix="gdb -ex run --args"),
        Node(package="demo", executable="listener"),
    ]
    labels = [s.label for s in run(entities, prefix, temp_dir).processes()]
    assert labels == ["speaker-1", "gdb-2", "listener-3"]


def test_node_without_package_runs_a_path_with_its_arguments(prefix: Path, temp_dir: str) -> None:
    node = Node(executable=sys.executable, arguments=["-c", "pass"], name="py")
    spec = only(run([node], prefix, temp_dir))
    assert spec.argv == (sys.executable, "-c", "pass", "--ros-args", "-r", "__node:=py")
    assert spec.node is not None and spec.node.package is None
    assert spec.label == os.path.basename(sys.executable) + "-1"


def test_lifecycle_node_needs_name_and_namespace(prefix: Path, temp_dir: str) -> None:
    with pytest.raises(TypeError):
        LifecycleNode(package="demo", executable="talker", name="x")  # type: ignore[call-arg]
    node = LifecycleNode(
        package="demo", executable="talker", name="lc", namespace="", autostart=True
    )
    spec = only(run([node], prefix, temp_dir))
    assert spec.node is not None
    assert (spec.node.lifecycle, spec.node.autostart) == (True, True)
    assert spec.node.fully_qualified_name == "/lc"
    assert node.node_name == "/lc"
    assert matches_node_name("/lc")(node) and matches_node_name("/lc")(spec)
    assert not matches_node_name("/other")(spec)


def test_lifecycle_events_as_data() -> None:
    node = LifecycleNode(package="demo", executable="talker", name="lc", namespace="ns")
    event = ChangeState(lifecycle_node_matcher=matches_node_name("/ns/lc"), transition_id=1)
    assert event.transition_name == "TRANSITION_CONFIGURE"
    with pytest.raises(ValueError, match="given transition_id of 42"):
        ChangeState(lifecycle_node_matcher=matches_node_name("/ns/lc"), transition_id=42)
    handler = OnStateTransition(target_lifecycle_node=node, goal_state="inactive", entities=[])
    assert handler.kind == "state_transition" and handler.target_action is node
    hit = StateTransition(
        action=node, transition="configure", start_state="configuring", goal_state="inactive"
    )
    miss = StateTransition(action=node, transition="activate", goal_state="active")
    assert handler.matches(hit) and not handler.matches(miss)
    with pytest.raises(TypeError, match="requires a LifecycleNode"):
        OnStateTransition(target_lifecycle_node=Node(executable="x"), entities=[])


# --- params files on disk -----------------------------------------------------------------------


def test_missing_params_file_is_skipped_with_a_located_warning(prefix: Path, temp_dir: str) -> None:
    node = Node(
        package="demo",
        executable="talker",
        parameters=["/does/not/exist.yaml", ParameterFile("/nor/this.yaml")],
    )
    plan = run([node], prefix, temp_dir)
    assert ros_part(only(plan)) == ["--ros-args"]
    assert plan.warnings == [
        f"{node.origin}: Parameter file path is not a file: /does/not/exist.yaml (skipped)",
        f"{node.origin}: Parameter file path is not a file: /nor/this.yaml (skipped)",
    ]


def test_parameter_file_with_substitutions_is_written_substituted(
    prefix: Path, temp_dir: str, tmp_path: Path
) -> None:
    source = tmp_path / "robot.yaml"
    source.write_text("/**:\n  ros__parameters:\n    frame: $(var robot)_base\n    rate: 10\n")
    node = Node(
        package="demo",
        executable="talker",
        parameters=[ParameterFile(str(source), allow_substs=True), ParameterFile(source)],
    )
    spec = only(run([node], prefix, temp_dir, args={"robot": "r2"}))
    ros = list(spec.argv)
    copied, given = (ros[i + 1] for i, a in enumerate(ros) if a == "--params-file")
    assert os.path.dirname(copied) == temp_dir
    assert (
        Path(copied).read_text() == "/**:\n  ros__parameters:\n    frame: r2_base\n    rate: 10\n"
    )
    assert given == str(source)


def test_a_missing_global_params_file_fails_the_node_naming_where_it_was_given(
    prefix: Path, temp_dir: str
) -> None:
    action = SetParametersFromFile("/no/such/params.yaml")
    assert not run([action], prefix, temp_dir).processes()  # as ros2 launch: no node, no error
    node = Node(package="demo", executable="talker")
    with pytest.raises(
        SubstitutionFailure,
        match=r"file '/no/such/params.yaml' does not exist \(given by SetParametersFromFile at"
        r" .*test_ros_node_argv.py:\d+\)",
    ):
        run([action, node], prefix, temp_dir)


def test_without_a_run_directory_params_files_go_to_a_private_one(prefix: Path) -> None:
    node = Node(package="demo", executable="talker", parameters=[{"a": 1}])
    spec = only(run([node], prefix, None))
    try:
        (written,) = [a for a in spec.argv if os.path.basename(a).startswith("launch_params_")]
        private = os.path.dirname(written)
        assert spec.temp_files == (written, private)
        assert os.path.basename(private).startswith("mlaunch-params-")
        assert Path(written).read_text() == "/**:\n  ros__parameters:\n    a: 1\n"
    finally:
        for path in spec.temp_files:
            if os.path.isfile(path):
                os.remove(path)
            elif os.path.isdir(path):
                os.rmdir(path)


# --- packages, executables, stand-ins ---------------------------------------------------------


def test_missing_package_names_what_was_searched(prefix: Path, temp_dir: str) -> None:
    node = Node(package="no_such_pkg_xyz", executable="run_me")
    with pytest.raises(PackageNotFoundError) as err:
        run([node], prefix, temp_dir)
    text = str(err.value)
    assert "package 'no_such_pkg_xyz' not found, wanted for executable 'run_me'" in text
    assert f"ament prefixes searched: {prefix}" in text
    assert "--package-path DIR" in text and "MLAUNCH_PACKAGE_PATH" in text
    assert err.value.where == node.origin
    assert err.value.what == "Node(package='no_such_pkg_xyz', executable='run_me')"
    assert isinstance(err.value, KeyError)  # as ament_index_python's error is


def test_missing_executable_lists_what_the_package_has(prefix: Path, temp_dir: str) -> None:
    with pytest.raises(PackageNotFoundError) as err:
        run([Node(package="demo", executable="talkr")], prefix, temp_dir)
    libexec = prefix / "lib" / "demo"
    assert (
        f"executable 'talkr' not found in package 'demo' (did you mean 'talker'?) (looked in"
        f" '{libexec}'; it has:"
        " listener, talker)" in str(err.value)
    )


def test_package_without_lib_folder(prefix: Path, temp_dir: str) -> None:
    make_prefix(prefix, {"nolib": []})
    (prefix / "lib" / "nolib").rmdir()
    with pytest.raises(PackageNotFoundError, match="its executable folder .* does not exist"):
        run([Node(package="nolib", executable="x")], prefix, temp_dir)


def test_standin_replaces_a_missing_package(
    prefix: Path, temp_dir: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(standins, "rclpy_available", lambda: True)
    node = Node(
        package="robot_state_publisher",
        executable="robot_state_publisher",
        parameters=[{"use_sim_time": True}],
    )
    spec = only(run([node], prefix, temp_dir))
    assert spec.argv[:3] == (sys.executable, "-m", "mlaunch.standins.rsp")
    assert spec.argv[3] == "--ros-args"
    assert spec.standin == "robot_state_publisher/robot_state_publisher"
    assert spec.label == "robot_state_publisher-1"
    assert spec.node is not None and spec.node.package == "robot_state_publisher"


def test_installed_package_wins_over_its_standin(
    prefix: Path, temp_dir: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(standins, "rclpy_available", lambda: True)
    make_prefix(prefix, {"robot_state_publisher": ["robot_state_publisher"]})
    spec = only(
        run(
            [Node(package="robot_state_publisher", executable="robot_state_publisher")],
            prefix,
            temp_dir,
        )
    )
    assert spec.argv == (
        str(prefix / "lib/robot_state_publisher/robot_state_publisher"),
        "--ros-args",
    )
    assert spec.standin is None


def test_no_standins_gives_an_error_with_a_hint(
    prefix: Path, temp_dir: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(standins, "rclpy_available", lambda: True)
    node = Node(package="rviz2", executable="rviz2")
    with pytest.raises(PackageNotFoundError, match="run without --no-standins"):
        run([node], prefix, temp_dir, standins=False)


def test_source_only_package_executable_is_not_built(
    prefix: Path, temp_dir: str, tmp_path: Path
) -> None:
    pkg = tmp_path / "src" / "my_robot"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text('<package format="3"><name>my_robot</name></package>')
    node = Node(package="my_robot", executable="driver")
    with pytest.raises(
        PackageNotFoundError, match=r"'my_robot' is only a source package at .* \(not built\)"
    ):
        run([node], prefix, temp_dir, packages=PackageSearch([str(tmp_path / "src")]))


def test_find_package_share_joins_with_slash(prefix: Path, temp_dir: str) -> None:
    from mlaunch.launch.launch_context import LaunchContext

    ctx = LaunchContext(environment={"AMENT_PREFIX_PATH": str(prefix)})
    joined = FindPackageShare("demo") / "launch" / TextSubstitution(text="x.launch.py")
    assert perform(ctx, joined) == str(prefix / "share" / "demo" / "launch" / "x.launch.py")


def test_text_values_rcl_would_retype_are_quoted(prefix: Path, temp_dir: str) -> None:
    """launch_ros writes plain y, 1e3, inf: rcl reads a bool or doubles. mlaunch quotes them."""
    from mlaunch.launch_ros.params import rcl_reads_as_text

    node = Node(
        package="demo",
        executable="talker",
        parameters=[
            {"y": "y", "sci": "1e3", "words": ["n", "inf", "ok"], "plain": "ok", "n": 2},
            Parameter("axis", "Y"),
        ],
    )
    spec = only(run([node], prefix, temp_dir))
    ros = ros_part(spec)
    assert ros[2][5:] == textwrap.dedent(
        """\
        /**:
          ros__parameters:
            n: 2
            plain: ok
            sci: '1e3'
            words:
            - 'n'
            - 'inf'
            - ok
            y: 'y'
        """
    )
    assert ros[3:] == ["-p", "axis:='Y'\n"]
    for text in ("y", "N", "TRUE", "Off", "1e3", "-inf", "NaN", "0x1A", "017", "08", " 5", ".5"):
        assert not rcl_reads_as_text(text), text
    for text in ("5 ", "abc", "1_000", "0x", "1e", "y2", "true story"):
        assert rcl_reads_as_text(text), text
