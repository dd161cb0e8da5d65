"""``launch.frontend`` from Python: Parser.load picks the XML or YAML reader, parse_description
builds the same description as ``mlaunch FILE`` loads, Entity reads attributes as upstream's
does, and what a parse leaves unread is an upstream error type with file:line."""

from __future__ import annotations

import io
import textwrap
from pathlib import Path
from typing import Any, List  # noqa: UP035 - upstream passes typing.list[...]

import pytest

from mlaunch import readers
from mlaunch.frontends import launch_xml, launch_yaml
from mlaunch.launch import actions
from mlaunch.launch.frontend import Entity, InvalidFrontendLaunchFileError, Parser, type_utils
from mlaunch.launch.frontend.parse_substitution import (
    parse_if_substitutions,
    parse_substitution,
    replace_escaped_characters,
)
from mlaunch.launch.substitution import TextSubstitution
from mlaunch.launch.substitutions import EnvironmentVariable, LaunchConfiguration

XML = """\
<launch deprecated="old">
  <arg name="who" default="world"/>
  <group scoped="false">
    <log message="hello $(var who)"/>
  </group>
  <executable cmd="echo a b" name="e" output="screen"/>
</launch>
"""

YAML = """\
launch:
- arg: {name: who, default: world}
- group:
    scoped: false
    children:
    - log: {message: "hello $(var who)"}
- executable: {cmd: echo a b, name: e, output: screen}
"""


def shape(entity: Any) -> Any:
    """Types and sub-entities of a description, enough to compare two of them."""
    subs = getattr(entity, "entities", None) or getattr(entity, "actions", None) or []
    return (type(entity).__name__, [shape(s) for s in subs])


@pytest.mark.parametrize(("name", "text"), [("t.launch.xml", XML), ("t.launch.yaml", YAML)])
def test_load_by_path_builds_what_the_reader_builds(tmp_path: Path, name: str, text: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    root, parser = Parser.load(str(path))
    assert isinstance(root, Entity) and root.type_name == "launch"
    expected = launch_xml.Parser if name.endswith("xml") else launch_yaml.Parser
    assert type(parser) is expected
    description = parser.parse_description(root)
    assert shape(description) == shape(readers.load(str(path)))
    assert isinstance(description.entities[0], actions.DeclareLaunchArgument)
    assert description.entities[0].origin == f"{path}:2"


@pytest.mark.parametrize("text", [XML, YAML])
def test_load_from_a_stream_tries_each_format(text: str) -> None:
    root, parser = Parser.load(io.StringIO(text))
    description = parser.parse_description(root)
    assert [type(e).__name__ for e in description.entities] == [
        "DeclareLaunchArgument",
        "GroupAction",
        "ExecuteProcess",
    ]
    if text is XML:
        assert description.deprecated_reason == "old"


def test_nothing_reads_it_names_each_implementations_error() -> None:
    with pytest.raises(InvalidFrontendLaunchFileError) as caught:
        Parser.load(io.StringIO("{not: [a launch file"))
    assert "syntax error, or its format is unknown" in str(caught.value)
    named = tmp_named("x.launch.xml", "<launch><log message='x'></launch>")
    with pytest.raises(InvalidFrontendLaunchFileError) as caught:
        Parser.load(named)
    assert "format [xml]" in str(caught.value)
    assert "x.launch.xml:1:" in str(caught.value)


def tmp_named(name: str, text: str) -> io.StringIO:
    stream = io.StringIO(text)
    stream.name = name  # type: ignore[misc]
    return stream


def test_implementations_come_from_entry_points() -> None:
    assert {"xml", "yaml"} <= set(Parser.get_available_extensions())
    assert Parser.get_parsers_from_filename("a.launch.xml") == [launch_xml.Parser]
    assert Parser.get_parsers_from_filename("a.yml") == [launch_yaml.Parser]
    assert Parser.is_filename_valid("a.launch.yaml")
    assert not Parser.is_filename_valid("a.txt")
    assert {"xml", "yaml", "launch.xml"} <= Parser.get_file_extensions_from_parsers()


def root_of(text: str) -> Entity:
    root, _ = Parser.load(io.StringIO(textwrap.dedent(text)))
    return root


def test_xml_entity_coerces_text_to_the_type_asked_for() -> None:
    root = root_of(
        """\
        <launch>
          <thing n="3" x="2.5" b="1" nums="1,2,3" nums-sep="," y="[1, 2]" s="$(var a)">
            <item v="a"/><item v="b"/>
          </thing>
        </launch>
        """
    )
    (thing,) = root.children
    assert thing.type_name == "thing" and thing.parent is root
    assert thing.get_attr("n", data_type=int) == 3
    assert thing.get_attr("x", data_type=float) == 2.5
    assert thing.get_attr("b", data_type=bool) is True
    assert thing.get_attr("nums", data_type=list[int]) == [1, 2, 3]
    assert thing.get_attr("y", data_type=None) == [1, 2]
    assert thing.get_attr("s") == "$(var a)"
    assert thing.get_attr("missing", optional=True) is None
    items = thing.get_attr("item", data_type=list[Entity])
    assert [i.get_attr("v") for i in items] == ["a", "b"]
    assert items[0].parent is thing
    thing.assert_entity_completely_parsed()


def test_xml_entity_errors_are_upstreams_types_and_located() -> None:
    root = root_of('<launch>\n  <thing n="many" z="1"/>\n</launch>\n')
    (thing,) = root.children
    with pytest.raises(TypeError) as bad:
        thing.get_attr("n", data_type=int, can_be_str=False)
    assert "<stream>:2:" in str(bad.value) and "'many'" in str(bad.value)
    with pytest.raises(AttributeError) as missing:
        thing.get_attr("name")
    assert "<stream>:2:3" in str(missing.value)
    with pytest.raises(ValueError) as left:
        thing.assert_entity_completely_parsed()
    assert "unknown attribute 'z'" in str(left.value)


def test_yaml_entity_checks_types_instead_of_coercing() -> None:
    root = root_of(
        """\
        launch:
        - thing:
            n: 3
            flag: true
            words: [a, b]
            text: '3'
            item: [{v: a}, {v: b}]
        """
    )
    (thing,) = root.children
    assert thing.get_attr("n", data_type=int) == 3
    assert thing.get_attr("flag", data_type=bool) is True
    assert thing.get_attr("words", data_type=list[str]) == ["a", "b"]
    with pytest.raises(TypeError):
        thing.get_attr("text", data_type=int, can_be_str=False)
    items = thing.get_attr("item", data_type=list[Entity])
    assert [i.get_attr("v") for i in items] == ["a", "b"]
    with pytest.raises(ValueError) as childless:
        _ = items[0].children
    assert "children" in str(childless.value)


def test_unread_parts_name_the_tag_as_upstream_does() -> None:
    root, parser = Parser.load(io.StringIO("<launch>\n<arg name='a' colour='x'/>\n</launch>"))
    with pytest.raises(ValueError) as caught:
        parser.parse_description(root)
    assert "`arg`" in str(caught.value) and "colour" in str(caught.value)
    assert str(caught.value).startswith("<stream>:2:")
    root, parser = Parser.load(
        io.StringIO("<launch><executable cmd='ls'><oops/></executable></launch>")
    )
    with pytest.raises(ValueError) as caught:
        parser.parse_description(root)
    assert "`executable`" in str(caught.value) and "<oops>" in str(caught.value)


def test_parse_substitution_returns_substitutions() -> None:
    assert [s.perform(None) for s in parse_substitution("")] == [""]  # type: ignore[arg-type]
    subs = parse_substitution("a_$(env HOME x)_b")
    assert [type(s) for s in subs] == [TextSubstitution, EnvironmentVariable, TextSubstitution]
    nested = parse_substitution("$(var 'p $(var q)')")
    assert isinstance(nested[0], LaunchConfiguration)
    assert replace_escaped_characters(r"a\$b\\c") == r"a$b\c"


def test_parse_if_substitutions_keeps_plain_values() -> None:
    assert parse_if_substitutions(4) == 4
    assert parse_if_substitutions("text") == "text"
    assert isinstance(parse_if_substitutions("$(var a)")[0], LaunchConfiguration)
    mixed = parse_if_substitutions(["$(var a)", "b"])
    assert isinstance(mixed[0][0], LaunchConfiguration) and mixed[1] == "b"
    with pytest.raises(ValueError):
        parse_if_substitutions(["a", 1, 1.5])


def test_type_utils() -> None:
    assert type_utils.check_is_list_entity(list[Entity])
    assert not type_utils.check_is_list_entity(list[int])
    assert type_utils.get_data_type_from_identifier("list_of_int") == List[int]  # noqa: UP006
    assert type_utils.get_data_type_from_identifier("yaml") is None
    with pytest.raises(ValueError):
        type_utils.get_data_type_from_identifier("complex")


def test_execute_process_parse_cmdline_splits_on_spaces_outside_substitutions() -> None:
    argv = actions.ExecuteProcess._parse_cmdline("$(env A)/x b  c$(env B) ", launch_xml.Parser())
    assert [[type(s).__name__ for s in item] for item in argv] == [
        ["EnvironmentVariable", "TextSubstitution"],
        ["TextSubstitution"],
        ["TextSubstitution", "EnvironmentVariable"],
    ]


@pytest.mark.parametrize(("name", "text"), [("s.launch.xml", XML), ("s.launch.yaml", YAML)])
def test_a_source_outside_a_run_is_read_through_launch_frontend(
    tmp_path: Path, name: str, text: str
) -> None:
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.launch_description_sources import (
        AnyLaunchDescriptionSource,
        FrontendLaunchDescriptionSource,
    )

    path = tmp_path / name
    path.write_text(text)
    for source in (
        AnyLaunchDescriptionSource(str(path)),
        FrontendLaunchDescriptionSource(str(path)),
    ):
        description = source.get_launch_description(LaunchContext())
        assert shape(description) == shape(readers.load(str(path)))


def test_on_exit_shutdown_is_the_process_sub_entity() -> None:
    root, parser = Parser.load(
        io.StringIO('<launch><executable cmd="ls" on_exit="shutdown"/></launch>')
    )
    (process,) = parser.parse_description(root).entities
    (shutdown,) = process.get_sub_entities()
    assert isinstance(shutdown, actions.Shutdown)
    assert actions.ExecuteProcess(cmd=["ls"], on_exit=shutdown).get_sub_entities() == []


def test_a_markup_parser_knows_launch_ros_substitutions_too() -> None:
    from mlaunch.launch_ros.substitutions import FindPackageShare

    parser = launch_yaml.Parser()
    (share,) = parser.parse_substitution("$(find-pkg-share demo)")
    assert isinstance(share, FindPackageShare)
    values = parser.parse_if_substitutions(["$(find-pkg-share demo)", "x"])
    assert isinstance(values[0][0], FindPackageShare) and values[1] == "x"
