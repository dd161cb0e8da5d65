"""Groups and includes return the actions that scope them, as upstream's; a visit of that list
in order is their whole effect, for a bare LaunchContext and for the resolver alike."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pytest

from mlaunch.launch.actions import (
    Action,
    DeclareLaunchArgument,
    GroupAction,
    IncludeLaunchDescription,
    LaunchDescription,
    LogInfo,
    PopEnvironment,
    PopLaunchConfigurations,
    PushEnvironment,
    PushLaunchConfigurations,
    ResetEnvironment,
    ResetLaunchConfigurations,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
)
from mlaunch.launch.conditions import IfCondition
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.launch_description_sources import LaunchDescriptionSource
from mlaunch.launch.substitutions import (
    EnvironmentVariable,
    LaunchConfiguration,
    ThisLaunchFileDir,
    perform_substitutions,
)
from mlaunch.plan.errors import LaunchArgumentError, LaunchFileError
from mlaunch.plan.steps import Log
from mlaunch.resolve.resolver import ResolveOptions, resolve

ENV = {"PATH": os.environ.get("PATH", ""), "HOME": "/home/u"}


def kinds(entities: list[Any] | None) -> list[str]:
    return [type(e).__name__ for e in entities or ()]


def visit(entity: Action, context: LaunchContext) -> list[Any]:
    """What visiting ``entity`` returns (a group or an include always returns a list)."""
    returned = entity.visit(context)
    assert returned is not None
    return returned


def test_a_scoped_group_returns_its_actions_between_push_and_pop() -> None:
    inner = LogInfo(msg="x")
    returned = visit(GroupAction([inner], launch_configurations={"k": "v"}), LaunchContext())
    assert kinds(returned) == [
        "PushLaunchConfigurations",
        "PushEnvironment",
        "SetLaunchConfiguration",
        "LogInfo",
        "PopEnvironment",
        "PopLaunchConfigurations",
    ]
    assert returned[3] is inner


def test_an_unscoped_group_returns_its_configurations_then_its_actions() -> None:
    inner = Action()
    returned = GroupAction([inner], scoped=False, launch_configurations={"a": "1", "b": "2"})
    assert kinds(returned.visit(LaunchContext())) == [
        "SetLaunchConfiguration",
        "SetLaunchConfiguration",
        "Action",
    ]
    assert GroupAction([], scoped=False).visit(LaunchContext()) == []


def test_visiting_what_a_scoped_group_returns_leaves_nothing_behind() -> None:
    context = LaunchContext(environment={"KEEP": "1"})
    context.launch_configurations["outer"] = "o"
    group = GroupAction(
        [SetLaunchConfiguration("inside", "i"), SetEnvironmentVariable("NEW", "n")],
        launch_configurations={"given": LaunchConfiguration("outer")},
    )
    returned = visit(group, context)
    for entity in returned[:-2]:
        entity.visit(context)
    assert context.launch_configurations == {"outer": "o", "given": "o", "inside": "i"}
    assert context.environment == {"KEEP": "1", "NEW": "n"}
    for entity in returned[-2:]:
        entity.visit(context)
    assert context.launch_configurations == {"outer": "o"}
    assert context.environment == {"KEEP": "1"}


def test_a_group_not_forwarding_resets_and_keeps_what_it_is_given() -> None:
    context = LaunchContext(environment={"BASE": "b"})
    context.launch_configurations.update(outer="o", other="x")
    SetEnvironmentVariable("ADDED", "a").visit(context)
    group = GroupAction(
        [LogInfo(msg="in")],
        forwarding=False,
        launch_configurations={"kept": LaunchConfiguration("outer"), "new": "n"},
    )
    returned = visit(group, context)
    assert kinds(returned) == [
        "PushLaunchConfigurations",
        "PushEnvironment",
        "ResetEnvironment",
        "ResetLaunchConfigurations",
        "LogInfo",
        "PopEnvironment",
        "PopLaunchConfigurations",
    ]
    for entity in returned[:4]:
        entity.visit(context)
    assert context.launch_configurations == {"kept": "o", "new": "n"}
    assert context.environment == {"BASE": "b"}
    for entity in returned[4:]:
        entity.visit(context)
    assert context.launch_configurations == {"outer": "o", "other": "x"}
    assert context.environment == {"BASE": "b", "ADDED": "a"}


def test_flags_written_as_substitutions_decide_the_shape_when_visited() -> None:
    context = LaunchContext()
    context.launch_configurations["s"] = "false"
    group = GroupAction([Action()], scoped=LaunchConfiguration("s"))
    assert kinds(group.visit(context)) == ["Action"]
    context.launch_configurations["s"] = "true"
    assert kinds(group.visit(context))[:2] == ["PushLaunchConfigurations", "PushEnvironment"]


def test_the_pairs_are_distinct_classes() -> None:
    assert not issubclass(PushEnvironment, PushLaunchConfigurations)
    assert not issubclass(PopEnvironment, PopLaunchConfigurations)
    assert not issubclass(ResetEnvironment, ResetLaunchConfigurations)


def test_an_include_returns_its_arguments_then_the_description() -> None:
    description = LaunchDescription([])
    context = LaunchContext()
    context.launch_configurations["where"] = "here"
    include = IncludeLaunchDescription(
        LaunchDescriptionSource(description),
        launch_arguments={"a": LaunchConfiguration("where"), "b": "2"}.items(),
    )
    returned = visit(include, context)
    assert kinds(returned) == [
        "SetLaunchConfiguration",
        "SetLaunchConfiguration",
        "LaunchDescription",
    ]
    assert returned[2] is description
    first = returned[0]
    assert perform_substitutions(context, first.name) == "a"
    assert perform_substitutions(context, first.value) == "here"
    assert IncludeLaunchDescription(LaunchDescriptionSource(description)).visit(context) == [
        description
    ]


def test_an_include_points_the_locals_at_the_included_file(tmp_path: Path) -> None:
    child = tmp_path / "child.launch.py"
    child.write_text("")
    context = LaunchContext()
    IncludeLaunchDescription(LaunchDescriptionSource(LaunchDescription(), str(child))).visit(
        context
    )
    assert context.locals.current_launch_file_path == str(child)
    assert context.locals.current_launch_file_directory == str(tmp_path)
    # A location that is no file is passed along as it is.
    IncludeLaunchDescription(LaunchDescriptionSource(LaunchDescription(), "<made>")).visit(context)
    assert context.locals.current_launch_file_directory == "<made>"


def test_an_include_missing_a_required_argument_says_which_and_what_was_given() -> None:
    needs = LaunchDescription([DeclareLaunchArgument("needed")])
    include = IncludeLaunchDescription(
        LaunchDescriptionSource(needs), launch_arguments=[("other", "1")]
    )
    with pytest.raises(RuntimeError, match="missing required argument 'needed'") as caught:
        include.visit(LaunchContext())
    assert isinstance(caught.value, LaunchArgumentError)
    assert "[other]" in str(caught.value)


def test_arguments_with_defaults_under_conditions_or_given_deeper_are_not_required() -> None:
    defaulted = LaunchDescription([DeclareLaunchArgument("d", default_value="x")])
    conditional = LaunchDescription([DeclareLaunchArgument("c", condition=IfCondition("false"))])
    deeper = IncludeLaunchDescription(
        LaunchDescriptionSource(LaunchDescription([DeclareLaunchArgument("n")])),
        launch_arguments=[("n", "1")],
    )
    for description in (defaulted, conditional, LaunchDescription([deeper])):
        IncludeLaunchDescription(LaunchDescriptionSource(description)).visit(LaunchContext())


def test_a_reset_hides_what_follows_from_the_check() -> None:
    after_reset = LaunchDescription(
        [ResetLaunchConfigurations(), SetLaunchConfiguration("r", "1"), DeclareLaunchArgument("r")]
    )
    IncludeLaunchDescription(LaunchDescriptionSource(after_reset)).visit(LaunchContext())


def test_a_configuration_of_the_includer_does_not_satisfy_the_included_file() -> None:
    """As ros2 launch: an argument reaches an included file only when the include passes it."""
    needs = LaunchDescription([DeclareLaunchArgument("needed")])
    parent = LaunchDescription([IncludeLaunchDescription(LaunchDescriptionSource(needs))])
    with pytest.raises(LaunchArgumentError, match="missing required argument 'needed'"):
        resolve(parent, path=None, arguments={"needed": "1"}, environ=ENV)


def _includer_and_child(tmp_path: Path) -> tuple[LaunchDescription, Path]:
    """A description (of ``parent.launch.py``) that includes sub/child.launch.py, giving it
    ThisLaunchFileDir as an argument, then logs ThisLaunchFileDir."""
    (tmp_path / "sub").mkdir()
    child = tmp_path / "sub" / "child.launch.py"
    child.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import LogInfo\n"
        "from launch.substitutions import LaunchConfiguration, ThisLaunchFileDir\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([LogInfo(msg=[LaunchConfiguration('x'), ' ',"
        " ThisLaunchFileDir()])])\n"
    )
    include = IncludeLaunchDescription(str(child), launch_arguments={"x": ThisLaunchFileDir()})
    include.origin = f"{tmp_path / 'parent.launch.py'}:7"
    after = LogInfo(msg=["after ", ThisLaunchFileDir(), " ", EnvironmentVariable("HOME")])
    after.origin = f"{tmp_path / 'parent.launch.py'}:8"
    return LaunchDescription([include, after]), tmp_path / "parent.launch.py"


def test_an_include_leaves_the_locals_at_the_included_file_as_jazzy(tmp_path: Path) -> None:
    """ros2/launch#618 in Jazzy: the argument and the action after the include see the
    included file's folder; mlaunch says so once at each place, naming the opt-in."""
    description, parent = _includer_and_child(tmp_path)
    plan = resolve(description, path=str(parent), arguments={}, environ=ENV)
    messages = [s.message for s in plan.steps if isinstance(s, Log)]
    sub = tmp_path / "sub"
    assert messages == [f"{sub} {sub}", f"after {sub} /home/u"]
    warned = [w for w in plan.warnings if "ThisLaunchFileDir" in w]
    assert [w.split(": ")[0] for w in warned] == [f"{parent}:7", f"{parent}:8"]
    assert all("--scoped-file-locals" in w and f"includer's {tmp_path}" in w for w in warned)


def test_scoped_file_locals_give_the_includer_its_locals(tmp_path: Path) -> None:
    """PR #862's rule, on request: the argument and what follows are the includer's."""
    description, parent = _includer_and_child(tmp_path)
    options = ResolveOptions(scoped_file_locals=True)
    plan = resolve(description, path=str(parent), arguments={}, environ=ENV, options=options)
    messages = [s.message for s in plan.steps if isinstance(s, Log)]
    assert messages == [f"{tmp_path} {tmp_path / 'sub'}", f"after {tmp_path} /home/u"]
    assert not [w for w in plan.warnings if "ThisLaunchFileDir" in w]


def test_the_comment_in_the_includer_scopes_its_includes(tmp_path: Path) -> None:
    description, parent = _includer_and_child(tmp_path)
    parent.write_text("# mlaunch: scoped-file-locals\n")
    plan = resolve(description, path=str(parent), arguments={}, environ=ENV)
    messages = [s.message for s in plan.steps if isinstance(s, Log)]
    assert messages == [f"{tmp_path} {tmp_path / 'sub'}", f"after {tmp_path} /home/u"]


def test_no_warning_where_both_rules_agree(tmp_path: Path) -> None:
    """ThisLaunchFileDir inside the included file is its own under either rule."""
    description, parent = _includer_and_child(tmp_path)
    del description.entities[1]
    include = description.entities[0]
    assert isinstance(include, IncludeLaunchDescription)
    include.launch_arguments = [("x", "given")]
    plan = resolve(description, path=str(parent), arguments={}, environ=ENV)
    assert [s.message for s in plan.steps if isinstance(s, Log)] == [f"given {tmp_path / 'sub'}"]
    assert not [w for w in plan.warnings if "ThisLaunchFileDir" in w]


def test_a_default_outside_the_choices_is_refused_when_declared() -> None:
    with pytest.raises(RuntimeError, match="not in provided choices"):
        DeclareLaunchArgument("a", default_value="c", choices=["a", "b"])
    with pytest.raises(RuntimeError, match="Required launch argument 'a'"):
        DeclareLaunchArgument("a", choices=["a", "b"]).visit(LaunchContext())


def test_each_pop_restores_its_own_half() -> None:
    """As launch's two stacks: the configurations' pair leaves the environment alone, and the
    environment's pair the configurations."""
    context = LaunchContext(environment={"BASE": "b"})
    action: Action
    for action in (
        PushLaunchConfigurations(),
        SetLaunchConfiguration("inside", "i"),
        SetEnvironmentVariable("KEPT", "k"),
        PopLaunchConfigurations(),
    ):
        action.visit(context)
    assert context.launch_configurations == {}
    assert context.environment == {"BASE": "b", "KEPT": "k"}
    for action in (
        PushEnvironment(),
        SetLaunchConfiguration("kept", "k"),
        SetEnvironmentVariable("INSIDE", "i"),
        PopEnvironment(),
    ):
        action.visit(context)
    assert context.launch_configurations == {"kept": "k"}
    assert context.environment == {"BASE": "b", "KEPT": "k"}


def test_a_scoped_include_keeps_both_inside() -> None:
    inner = LaunchDescription(
        [SetLaunchConfiguration("inside", "i"), SetEnvironmentVariable("INSIDE", "i")]
    )
    context = LaunchContext(environment={"BASE": "b"})
    include = IncludeLaunchDescription(
        LaunchDescriptionSource(inner), launch_arguments=[("given", "g")], scoped=True
    )
    returned = visit(include, context)
    assert kinds(returned) == [
        "PushLaunchConfigurations",
        "PushEnvironment",
        "SetLaunchConfiguration",
        "LaunchDescription",
        "PopEnvironment",
        "PopLaunchConfigurations",
    ]
    for entity in returned:
        for inside in entity.visit(context) or ():  # the description gives its entities
            inside.visit(context)
    assert context.launch_configurations == {}
    assert context.environment == {"BASE": "b"}


def test_what_is_no_launch_entity_is_said_by_the_resolver_not_the_include_check() -> None:
    included = LaunchDescription([DeclareLaunchArgument("a", default_value="1"), object()])
    parent = LaunchDescription([IncludeLaunchDescription(LaunchDescriptionSource(included))])
    with pytest.raises(LaunchFileError, match="is not a launch action"):
        resolve(parent, path=None, arguments={}, environ=ENV)
