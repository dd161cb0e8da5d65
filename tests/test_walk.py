"""The one walk of a description (mlaunch.launch.walk): order, conditional and deferred parts."""

from __future__ import annotations

from mlaunch.launch.actions import (
    DeclareLaunchArgument,
    GroupAction,
    IncludeLaunchDescription,
    LogInfo,
    RegisterEventHandler,
    TimerAction,
)
from mlaunch.launch.conditions import IfCondition
from mlaunch.launch.event_handlers import OnShutdown
from mlaunch.launch.launch_description import LaunchDescription
from mlaunch.launch.walk import walk


def _name(entity: object) -> str:
    if isinstance(entity, LogInfo):
        return "".join(getattr(s, "text", "?") for s in entity.msg)
    return type(entity).__name__


def _names(visits):
    return [(_name(v.entity), v.conditional, v.deferred) for v in visits]


def test_every_entity_in_written_order_with_where_it_runs():
    a = LogInfo(msg="a")
    b = LogInfo(msg="b", condition=IfCondition("true"))
    c = LogInfo(msg="c")
    d = LogInfo(msg="d")
    handler = RegisterEventHandler(OnShutdown(on_shutdown=[d]))
    description = LaunchDescription(
        [a, GroupAction([b, TimerAction(period=1.0, actions=[c])]), handler]
    )
    assert _names(walk([description])) == [
        ("LaunchDescription", False, False),
        ("a", False, False),
        ("GroupAction", False, False),
        ("b", True, False),
        ("TimerAction", False, False),
        ("c", True, True),
        ("RegisterEventHandler", False, False),
        ("d", True, True),
    ]


def test_an_entity_met_twice_is_walked_once():
    shared = LogInfo(msg="x")
    assert _names(walk([LaunchDescription([shared, GroupAction([shared])])])) == [
        ("LaunchDescription", False, False),
        ("x", False, False),
        ("GroupAction", False, False),
    ]


def test_includes_are_followed_only_as_the_caller_says():
    inner = LaunchDescription([DeclareLaunchArgument("deep")])
    include = IncludeLaunchDescription(inner, condition=IfCondition("false"))
    root = LaunchDescription([include])
    assert [type(v.entity).__name__ for v in walk([root])] == [
        "LaunchDescription",
        "IncludeLaunchDescription",
    ]
    asked: list[bool] = []

    def follow(entity: object, conditional: bool) -> list[object]:
        asked.append(conditional)
        return [inner]

    visits = list(walk([root], include=follow))
    assert asked == [True]
    assert [(type(v.entity).__name__, v.conditional) for v in visits][-1] == (
        "DeclareLaunchArgument",
        True,
    )
