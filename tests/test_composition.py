"""Composable nodes resolved: the exact LoadNode requests of Python, XML and YAML files, --print,
and the errors of bad descriptions. Pure: nothing starts; rclcpp_components is a fake prefix.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest

from mlaunch import readers
from mlaunch.launch.actions import LaunchDescription
from mlaunch.launch_ros.actions import ComposableNodeContainer, LoadComposableNodes
from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.launch_ros.descriptions.composable_node import ComposableNode
from mlaunch.launch_ros.load_request import (
    BOOL,
    DOUBLE,
    DOUBLE_ARRAY,
    INTEGER,
    STRING,
    STRING_ARRAY,
    LoadRequest,
    TypedParameter,
)
from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.plan.steps import Plan
from mlaunch.resolve.describe import describe_plan
from mlaunch.resolve.resolver import ResolveOptions, resolve
from mlaunch.ros import packages

HERE = Path(__file__).parent / "launches" / "composition"


@pytest.fixture(autouse=True)
def _fresh_packages() -> Iterator[None]:
    packages.forget_scans()
    yield
    packages.forget_scans()


@pytest.fixture
def prefix(tmp_path: Path) -> Path:
    """A fake ament prefix holding rclcpp_components' container executable."""
    root = tmp_path / "install"
    index = root / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "rclcpp_components").write_text("")
    (root / "share" / "rclcpp_components").mkdir(parents=True)
    exe = root / "lib" / "rclcpp_components" / "component_container"
    exe.parent.mkdir(parents=True)
    exe.write_text("#!/bin/sh\nexit 0\n")
    exe.chmod(0o755)
    return root


def plan_of(description: LaunchDescription, path: str | None, prefix: Path, **args: str) -> Plan:
    environ = {"PATH": os.environ["PATH"], "HOME": "/home/u", "AMENT_PREFIX_PATH": str(prefix)}
    return resolve(
        description, path=path, arguments=args, environ=environ, options=ResolveOptions()
    )


def loads(plan: Plan) -> list[tuple[str, tuple[LoadRequest, ...]]]:
    return [(s.target, s.requests) for s in plan.steps if isinstance(s, LoadComponents)]


def p(name: str, kind: int, value: object) -> TypedParameter:
    return TypedParameter(name, kind, value)


SIM_TIME = p("use_sim_time", BOOL, True)
FROM_FILE = (p("common", STRING, "x"), p("n", INTEGER, 3))

EXPECTED = [
    (
        "/my_container",
        (
            LoadRequest(
                "composition",
                "composition::Talker",
                "talker",
                "",
                0,
                ("chatter:=chat",),
                (
                    SIM_TIME,
                    p("a", INTEGER, 1),
                    p("b.c", DOUBLE_ARRAY, (1.0, 2.0)),
                    *FROM_FILE,
                    p("own", STRING_ARRAY, ("a", "b")),
                ),
                (p("use_intra_process_comms", BOOL, True),),
            ),
            LoadRequest("composition", "composition::Listener", "listener", "", 0, (), (SIM_TIME,)),
        ),
    ),
    (
        "/my_container",
        (
            LoadRequest(
                "composition",
                "composition::Client",
                "client",
                "/robot",
                0,
                ("/tf:=tf",),
                (SIM_TIME, *FROM_FILE, p("rate", DOUBLE, 1.5)),
            ),
            LoadRequest(
                "composition",
                "composition::Server",
                "server",
                "/robot/srv",
                0,
                ("/tf:=tf",),
                (SIM_TIME, *FROM_FILE),
            ),
        ),
    ),
]


@pytest.mark.parametrize("suffix", ["py", "xml", "yaml"])
def test_requests_are_launch_ros_requests_in_every_frontend(suffix: str, prefix: Path) -> None:
    path = str(HERE / f"demo.launch.{suffix}")
    plan = plan_of(readers.load(path), path, prefix)
    (container,) = plan.processes()
    assert container.node is not None and container.node.fully_qualified_name == "/my_container"
    assert loads(plan) == EXPECTED


@pytest.mark.parametrize("suffix", ["py", "xml", "yaml"])
def test_a_false_condition_drops_that_node_only(suffix: str, prefix: Path) -> None:
    path = str(HERE / f"demo.launch.{suffix}")
    plan = plan_of(readers.load(path), path, prefix, with_listener="false")
    first = loads(plan)[0][1]
    assert [r.node_name for r in first] == ["talker"]


def test_target_container_name_is_used_as_given(prefix: Path) -> None:
    path = str(HERE / "demo.launch.py")
    plan = plan_of(readers.load(path), path, prefix, container="c2")
    assert [target for target, _ in loads(plan)] == ["/c2", "/c2"]


def test_print_shows_each_component_with_container_plugin_params_and_remaps(
    prefix: Path,
) -> None:
    path = str(HERE / "demo.launch.xml")
    text = describe_plan(plan_of(readers.load(path), path, prefix), path)
    assert "component /robot/client   (loaded into /my_container)" in text
    assert "  plugin:  composition::Client   (package composition)" in text
    assert "  remap:   /tf:=tf" in text
    assert "  param:   rate = 1.5" in text
    assert "  param:   own = ['a', 'b']" in text
    assert "  extra:   use_intra_process_comms = true" in text


def test_load_before_its_container_is_a_clear_error(prefix: Path) -> None:
    container = ComposableNodeContainer(
        name="c", namespace="", package="rclcpp_components", executable="component_container"
    )
    load = LoadComposableNodes(
        target_container=container,
        composable_node_descriptions=[ComposableNode(package="p", plugin="p::P")],
    )
    with pytest.raises(MlaunchError, match="must come after its container"):
        plan_of(LaunchDescription([load, container]), None, prefix)


def test_container_action_as_target_gives_its_full_name(prefix: Path) -> None:
    container = ComposableNodeContainer(
        name="c", namespace="ns", package="rclcpp_components", executable="component_container"
    )
    load = LoadComposableNodes(
        target_container=container,
        composable_node_descriptions=[ComposableNode(package="p", plugin="p::P")],
    )
    plan = plan_of(LaunchDescription([container, load]), None, prefix)
    ((target, (request,)),) = loads(plan)
    assert target == "/ns/c"
    assert (request.node_name, request.node_namespace) == ("", "")


def test_bad_descriptions_are_clear_errors() -> None:
    with pytest.raises(LaunchFileError, match="must be a list of ComposableNode"):
        LoadComposableNodes(
            target_container="c",
            composable_node_descriptions=ComposableNode(package="p", plugin="p::P"),  # type: ignore[arg-type]
        )
    with pytest.raises(LaunchFileError, match="target_container must be"):
        LoadComposableNodes(target_container=3, composable_node_descriptions=[])
    with pytest.raises(LaunchFileError, match="remapping must be a"):
        ComposableNode(package="p", plugin="p::P", remappings=["a"])


def test_a_value_loadnode_cannot_carry_is_a_clear_error(prefix: Path) -> None:
    load = LoadComposableNodes(
        target_container="c",
        composable_node_descriptions=[
            ComposableNode(package="p", plugin="p::P", name="n", parameters=[{"x": [1, "a"]}])
        ],
    )
    with pytest.raises(MlaunchError, match="parameter 'x'"):
        plan_of(LaunchDescription([load]), None, prefix)


def test_a_params_files_text_use_sim_time_is_sent_as_launch_ros_sends_it(
    tmp_path: Path, prefix: Path
) -> None:
    """Written in the launch file it is an error (every node rejects it); read from a params
    file it goes out as written, and the container refuses that one load (conformance case
    nav2_like)."""
    params = tmp_path / "p.yaml"
    params.write_text("/**:\n  ros__parameters:\n    use_sim_time: $(var x)\n")
    load = LoadComposableNodes(
        target_container="c",
        composable_node_descriptions=[
            ComposableNode(package="p", plugin="p::P", name="n", parameters=[str(params)])
        ],
    )
    ((_, (request,)),) = loads(plan_of(LaunchDescription([load]), None, prefix))
    assert request.parameters == (p("use_sim_time", STRING, "$(var x)"),)
    written = LoadComposableNodes(
        target_container="c",
        composable_node_descriptions=[
            ComposableNode(
                package="p", plugin="p::P", name="n", parameters=[{"use_sim_time": "maybe"}]
            )
        ],
    )
    with pytest.raises(MlaunchError, match="use_sim_time"):
        plan_of(LaunchDescription([written]), None, prefix)


@pytest.mark.parametrize("field", ["parameters", "extra_arguments"])
def test_a_parameter_description_is_refused_as_launch_ros_fails_on_it(
    field: str, tmp_path: Path, prefix: Path
) -> None:
    """launch_ros 0.26.6 keeps Parameter(...) unevaluated in a LoadNode request and fails
    ('invalid evaluated parameters', the launch ends with 1; checked with the reference): an
    error at the action's line, naming the value and what to write instead."""
    path = tmp_path / "param.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import LoadComposableNodes\n"
        "from launch_ros.descriptions import ComposableNode\n"
        "from launch_ros.parameter_descriptions import Parameter\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        "        LoadComposableNodes(target_container='c', composable_node_descriptions=[\n"
        "            ComposableNode(package='p', plugin='p::P', name='n',\n"
        f"                           {field}=[{{'x': 1}}, Parameter('y', 2)])]),\n"
        "    ])\n"
    )
    with pytest.raises(MlaunchError) as caught:
        plan_of(readers.load(str(path)), str(path), prefix)
    error = caught.value
    assert error.where == f"{path}:7"
    assert (
        f"a ComposableNode's {field} cannot hold launch_ros.description.Parameter(name='y',"
        " value=2, value_type=None)"
    ) in str(error)
    assert f"give it as a dict instead, {field}=[{{name: value}}]" in str(error)


def test_a_parameter_description_of_a_node_not_loaded_is_no_error(prefix: Path) -> None:
    """launch_ros builds no request for a node whose condition is false, so it never fails."""
    from mlaunch.launch.conditions import IfCondition
    from mlaunch.launch_ros.parameter_descriptions import Parameter

    node = ComposableNode(
        package="p",
        plugin="p::P",
        parameters=[Parameter("y", 2)],
        condition=IfCondition("false"),
    )
    load = LoadComposableNodes(target_container="c", composable_node_descriptions=[node])
    assert loads(plan_of(LaunchDescription([load]), None, prefix)) == []


def test_composable_node_at_top_level_says_where_it_belongs(tmp_path: Path) -> None:
    path = tmp_path / "t.launch.xml"
    path.write_text('<launch><composable_node pkg="p" plugin="p::P" name="n"/></launch>')
    with pytest.raises(LaunchFileError, match="inside <node_container> or <load_composable_node>"):
        readers.load(str(path))


def test_a_substituted_params_file_copy_is_removed_once_the_request_is_built(
    tmp_path: Path, prefix: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The copy with substitutions performed is read into the request and not needed after:
    it is removed (it was left in the temp folder, one per load, by every run)."""
    from mlaunch.launch_ros.parameter_descriptions import ParameterFile

    temp = tmp_path / "tmp"
    temp.mkdir()
    monkeypatch.setenv("TMPDIR", str(temp))
    monkeypatch.setattr("tempfile.tempdir", None)  # tempfile caches the folder it chose
    params = tmp_path / "p.yaml"
    params.write_text("/**:\n  ros__parameters:\n    rate: $(var x)\n")
    load = LoadComposableNodes(
        target_container="c",
        composable_node_descriptions=[
            ComposableNode(
                package="p",
                plugin="p::P",
                name="n",
                parameters=[ParameterFile(str(params), allow_substs=True)],
            )
        ],
    )
    ((_, (request,)),) = loads(plan_of(LaunchDescription([load]), None, prefix, x="3"))
    assert request.parameters == (p("rate", INTEGER, 3),)
    assert list(temp.iterdir()) == []
