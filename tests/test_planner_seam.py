"""The seam between a launch action and what executes it: visit(context) / execute(context)."""

from __future__ import annotations

import sys

from mlaunch.launch.actions import (
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    LogInfo,
    SetLaunchConfiguration,
    TimerAction,
)
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.launch_description import Action, LaunchDescription
from mlaunch.launch.planning import StandalonePlanner
from mlaunch.launch.substitutions import LaunchConfiguration
from mlaunch.plan.steps import Spawn, StartTimer
from mlaunch.resolve.resolver import resolve


def test_a_bare_context_plans_with_a_standalone_planner():
    context = LaunchContext()
    assert isinstance(context.planner, StandalonePlanner)
    assert context.planner is context.planner  # made once
    assert context.environment  # a copy of the launcher's environment


def test_visit_returns_what_to_visit_next_as_upstream():
    context = LaunchContext()
    inner = SetLaunchConfiguration("a", "1")
    description = LaunchDescription([inner])
    assert description.visit(context) == [inner]
    assert inner.visit(context) is None
    assert context.launch_configurations == {"a": "1"}


def test_an_action_visited_on_its_own_collects_its_steps():
    context = LaunchContext(environment={"PATH": "/usr/bin:/bin"})
    context.launch_configurations["prog"] = sys.executable
    process = ExecuteProcess(cmd=[LaunchConfiguration("prog"), "-c", "pass"], name="p")
    process.visit(context)
    timer = TimerAction(period=1.5, actions=[LogInfo(msg="later")])
    timer.visit(context)
    steps = context.planner.plan.steps  # type: ignore[attr-defined]
    assert [type(s) for s in steps] == [Spawn, StartTimer]
    assert steps[0].spec.argv[0] == sys.executable
    assert steps[0].spec.label == "p-1"


class _Extension(Action):
    """An action written against upstream: execute(context) reads and sets configurations."""

    def execute(self, context: LaunchContext) -> None:
        value = context.perform_substitution(LaunchConfiguration("robot"))
        context.launch_configurations["seen"] = value.upper()


def test_a_third_party_action_runs_against_the_run_context():
    description = LaunchDescription(
        [
            DeclareLaunchArgument("robot", default_value="jtbot"),
            GroupAction([_Extension(), LogInfo(msg=LaunchConfiguration("seen"))], scoped=False),
        ]
    )
    plan = resolve(description, path=None, arguments={}, environ={})
    assert [s.message for s in plan.steps if hasattr(s, "message")] == ["JTBOT"]


def test_the_resolver_is_the_planner_of_a_run_and_of_its_contexts():
    seen: list[object] = []

    class Probe(Action):
        def execute(self, context: LaunchContext) -> None:
            seen.append(type(context.planner).__name__)

    resolve(LaunchDescription([Probe()]), path=None, arguments={}, environ={})
    assert seen == ["Resolver"]
