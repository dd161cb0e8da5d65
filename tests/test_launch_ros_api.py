"""launch_ros's public API as extension code and unit tests use it: what SetParameter, Node,
ParameterFile, ParameterValue and ``launch_ros.utilities`` expose, and where mlaunch's run-time
checks differ from the public functions (a run keeps its located errors).

Pure: nothing starts a process; params files go to tmp_path.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import pytest
import yaml

from mlaunch.launch.actions import LaunchDescription
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.substitutions import (
    LaunchConfiguration,
    LocalSubstitution,
    TextSubstitution,
    perform_substitutions,
)
from mlaunch.launch_ros.actions import Node, SetParameter, SetParametersFromFile, SetRemap
from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile, ParameterValue
from mlaunch.launch_ros.utilities import evaluate_parameters, normalize_parameters
from mlaunch.plan.errors import SubstitutionFailure
from mlaunch.resolve.resolver import ResolveOptions, resolve
from mlaunch.ros import packages


class ConfigurationsOnly:
    """What some extension tests pass for a context: launch configurations, nothing else."""

    def __init__(self) -> None:
        self.launch_configurations: dict[str, Any] = {}


@pytest.fixture(autouse=True)
def _temp_files_in_tmp_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    packages.forget_scans()


def texts(context: Any, cmd: list[Any]) -> list[str]:
    """The plain-text items of a Node's cmd (not the executable or its local substitutions)."""
    return [perform_substitutions(context, i) for i in cmd if isinstance(i[0], TextSubstitution)]


# --- SetParameter ---------------------------------------------------------------------------


def test_set_parameter_exposes_its_name_and_value_normalized() -> None:
    action = SetParameter(
        name=["rate", TextSubstitution(text="_hz")], value=LaunchConfiguration("r")
    )
    assert [s.text for s in action.name] == ["rate", "_hz"]
    assert isinstance(action.value, tuple) and isinstance(action.value[0], LaunchConfiguration)
    plain = SetParameter(name="mode", value="fast")
    assert yaml.safe_load(perform_substitutions(LaunchContext(), plain.value)) == "fast"
    assert SetParameter(name="n", value=[1, 2.5]).value == (1.0, 2.5)


def test_set_parameter_from_xml_keeps_its_value_a_substitution(tmp_path: Path) -> None:
    from mlaunch.frontends import xml

    path = tmp_path / "p.launch.xml"
    path.write_text('<launch><set_parameter name="speed" value="12"/></launch>')
    (action,) = xml.load(str(path)).entities
    context = LaunchContext()
    assert perform_substitutions(context, action.value) == "12"
    action.execute(context)
    assert context.launch_configurations["global_params"] == [("speed", 12)]


# --- Node after its substitutions -------------------------------------------------------------


def test_node_cmd_lists_scope_and_own_parameters_then_remaps(tmp_path: Path) -> None:
    context: Any = ConfigurationsOnly()
    given = tmp_path / "scope.yaml"
    given.write_text("/**:\n  ros__parameters:\n    a: 1\n")
    SetParametersFromFile(str(given)).execute(context)
    SetParameter("speed", "fast").execute(context)
    SetRemap("scan", "base_scan").execute(context)
    node = Node(
        package="nowhere",
        executable="driver",
        name="drv",
        namespace="robot",
        parameters=[{"gain": 2}],
        remappings=[("cmd", "cmd_vel")],
    )
    node._perform_substitutions(context)
    items = texts(context, node.cmd)
    assert items[:6] == ["--ros-args", "-r", "-r", "--params-file", str(given), "-p"]
    assert items[6] == "speed:=fast" and items[7] == "--params-file"
    assert yaml.safe_load(Path(items[8]).read_text()) == {
        "/robot/drv": {"ros__parameters": {"gain": 2}}
    }
    assert items[9:] == ["-r", "scan:=base_scan", "-r", "cmd:=cmd_vel"]
    locals_ = [i[0].expression for i in node.cmd if isinstance(i[0], LocalSubstitution)]
    assert locals_ == ["ros_specific_arguments['name']", "ros_specific_arguments['ns']"]
    assert node.expanded_remapping_rules == [("scan", "base_scan"), ("cmd", "cmd_vel")]
    assert node._Node__expanded_parameter_arguments == [(str(given), True), (items[8], True)]  # type: ignore[attr-defined]


def test_node_without_remappings_has_none_and_a_resolution_replaces_the_last() -> None:
    context: Any = ConfigurationsOnly()
    node = Node(package="nowhere", executable="driver", arguments=["--fast"])
    node._perform_substitutions(context)
    node._perform_substitutions(context)
    assert node.expanded_remapping_rules is None
    assert texts(context, node.cmd) == ["--fast", "--ros-args"]


def test_node_refuses_bad_remappings_and_parameter_names_with_type_errors() -> None:
    for remappings in ({"a": "b"}, [{"a": "b"}], [["a", "b"]], "a:=b"):
        with pytest.raises(TypeError, match="remapping"):
            Node(package="p", executable="e", remappings=remappings)
    for parameters in ([{5: "x"}], [{"group": {"inner": {7: "x"}}}], [{"p": [1, [2]]}]):
        with pytest.raises(TypeError, match="parameter"):
            Node(package="p", executable="e", parameters=parameters)


def test_a_missing_scope_params_file_is_kept_as_given_until_a_node_uses_it() -> None:
    context = LaunchContext()
    SetParametersFromFile("./not-here.yaml").execute(context)
    assert context.launch_configurations["global_params"] == ["./not-here.yaml"]
    with pytest.raises(SubstitutionFailure, match=r"given by SetParametersFromFile at .*\.py:\d+"):
        Node(package="p", executable="e")._perform_substitutions(context)


# --- descriptions ---------------------------------------------------------------------------


def test_parameter_file_cleanup_removes_only_the_substituted_copy(tmp_path: Path) -> None:
    source = tmp_path / "p.yaml"
    source.write_text("/**:\n  ros__parameters:\n    who: $(env USER_NAME_X)\n")
    context = LaunchContext()
    context.environment["USER_NAME_X"] = "ada"
    copy = ParameterFile(str(source), allow_substs=True)
    written = copy.evaluate(context)
    assert written != source and "who: ada" in written.read_text()
    copy.cleanup()
    assert not written.exists() and isinstance(copy.param_file, list)
    plain = ParameterFile(str(source))
    assert plain.evaluate(context) == source
    plain.cleanup()
    assert source.exists() and plain.param_file == source


def test_parameter_values_show_substitutions_as_lists_and_fail_as_launch() -> None:
    value = ParameterValue(TextSubstitution(text="[4, 5]"))
    assert isinstance(value.value, list) and isinstance(value.value[0], TextSubstitution)
    assert value.evaluate(LaunchContext()) == [4, 5] and value.value == [4, 5]
    named = Parameter("p", ["x", TextSubstitution(text="y")], value_type=str)
    assert [type(v) for v in named.value] == [TextSubstitution, TextSubstitution]
    with pytest.raises(TypeError):
        ParameterValue("3", value_type=int)
    with pytest.raises(ValueError):
        ParameterValue(TextSubstitution(text="[4, five]")).evaluate(LaunchContext())
    with pytest.raises(ValueError):
        Parameter("p", TextSubstitution(text="{a: 1}")).evaluate(LaunchContext())


# --- launch_ros.utilities: the public shapes and errors ---------------------------------------


def test_normalize_parameters_gives_launch_ros_shapes() -> None:
    sub = TextSubstitution(text="x")
    (normalized,) = normalize_parameters(
        [{"a": {"b": 1}, "s": "t", "l": [sub, "y"], "m": [1, "u"]}]
    )
    keys = {perform_substitutions(LaunchContext(), k): v for k, v in normalized.items()}
    assert keys["a.b"] == 1
    assert isinstance(keys["s"], tuple) and isinstance(keys["s"][0], TextSubstitution)
    assert len(keys["l"]) == 2 and keys["l"][0] is sub
    assert all(isinstance(item, tuple) for item in keys["m"])
    (as_file,) = normalize_parameters(["/p.yaml"])
    assert isinstance(as_file, ParameterFile)


def evaluate(entry: dict[Any, Any]) -> Any:
    (result,) = evaluate_parameters(LaunchContext(), normalize_parameters([entry]))
    return result


def test_evaluate_parameters_types_lists_of_substitutions_item_by_item() -> None:
    a, b = TextSubstitution(text="a"), TextSubstitution(text="b")
    assert evaluate({"v": [[a, b], a]}) == {"v": ("ab", "a")}
    assert evaluate({"v": [a, b]}) == {"v": "ab"}
    assert evaluate({"v": [[TextSubstitution(text="3")], [TextSubstitution(text="4")]]}) == {
        "v": (3, 4)
    }


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ([1, True, 2.0], "Expected a non-empty sequence"),
        ([TextSubstitution(text="on"), 3], "Expected a non-empty sequence"),
        (TextSubstitution(text="[]"), "Expected a non-empty sequence"),
        (TextSubstitution(text="{k: 1}"), "Allowed value types"),
        (TextSubstitution(text="a: b: c"), "Unable to parse"),
    ],
)
def test_evaluate_parameters_refuses_what_is_no_parameter(value: Any, words: str) -> None:
    with pytest.raises(TypeError, match=words):
        evaluate({"v": value})


def test_a_run_keeps_its_located_parameter_errors(tmp_path: Path) -> None:
    node = Node(
        executable="/bin/true", parameters=[{"mixed": [1, True, TextSubstitution(text="s")]}]
    )
    with pytest.raises(SubstitutionFailure, match="parameter 'mixed' is the list"):
        resolve(
            LaunchDescription([node]),
            path=None,
            arguments={},
            environ={"PATH": os.environ["PATH"], "HOME": str(tmp_path)},
            options=ResolveOptions(temp_dir=str(tmp_path)),
        )
