"""The seam between a launch action and what executes it: visit(context) / execute(context)."""

from __future__ import annotations

import sys

from mlaunch.launch.action import Action
from mlaunch.launch.actions import (
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    LogInfo,
    SetLaunchConfiguration,
    TimerAction,
)
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.launch_description import LaunchDescription
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


def test_a_bare_context_holds_the_events_it_was_given_in_upstreams_queue():
    import asyncio

    from mlaunch.launch.actions import Shutdown
    from mlaunch.launch.conditions import IfCondition
    from mlaunch.launch.events import Shutdown as ShutdownEvent

    context = LaunchContext()
    assert isinstance(context._event_queue, asyncio.Queue) and context._event_queue.empty()
    assert Shutdown(reason="no", condition=IfCondition("false")).visit(context) is None
    assert context._event_queue.qsize() == 0
    assert Shutdown(reason="done").visit(context) is None
    other = object()
    asyncio.run(context.emit_event(other))
    queued = [context._event_queue.get_nowait() for _ in range(context._event_queue.qsize())]
    assert isinstance(queued[0], ShutdownEvent) and queued[0].reason == "done"
    assert queued[1] is other
    # The same events are steps of the standalone plan, in the same order.
    steps = context.planner.plan.steps  # type: ignore[attr-defined]
    assert [type(s).__name__ for s in steps] == ["RequestShutdown", "EmitEvent"]
    assert steps[0].reason == "done" and steps[1].event is other


def test_a_runs_context_plans_the_events_it_is_given_and_queues_none():
    from mlaunch.launch.actions import Shutdown

    sizes: list[int] = []

    class Probe(Action):
        def execute(self, context: LaunchContext) -> None:
            context.emit_event_sync(object())
            sizes.append(context._event_queue.qsize())

    plan = resolve(
        LaunchDescription([Probe(), Shutdown(reason="end")]), path=None, arguments={}, environ={}
    )
    assert sizes == [0]
    assert [type(s).__name__ for s in plan.steps] == ["EmitEvent", "RequestShutdown"]


def test_prepare_and_execute_fill_process_details_with_the_final_command():
    context = LaunchContext(environment={"PATH": "/usr/bin:/bin"})
    context.launch_configurations["launch-prefix"] = "nice -n 5"
    context.launch_configurations["launch-prefix-filter"] = "py.*"
    matched = ExecuteProcess(cmd=["python3", "-c", "pass"], name="m")
    missed = ExecuteProcess(cmd=["true"])
    own = ExecuteProcess(cmd=["true"], prefix="echo")
    assert matched.process_details is None  # as written before: substitutions
    assert [s.text for s in matched.name] == ["m"]
    assert [[s.text for s in item] for item in matched.cmd] == [["python3"], ["-c"], ["pass"]]
    matched.prepare(context)
    details = matched.process_details
    assert details is not None and details["action"] is matched
    assert details["cmd"] == ["nice", "-n", "5", "python3", "-c", "pass"]
    assert (matched.name, matched.cmd, matched.env) == (
        details["name"],
        details["cmd"],
        details["env"],
    )
    assert details["name"] == "m-1" and "pid" not in details
    assert context.planner.plan.steps == []  # type: ignore[attr-defined]  # prepared, not planned
    missed.visit(context)
    own.visit(context)
    assert missed.cmd == ["true"]  # the filter leaves a program it does not match alone
    assert own.cmd == ["echo", "true"]  # the action's own prefix is not filtered
    spawned = [s.spec.argv for s in context.planner.plan.steps]  # type: ignore[attr-defined]
    assert spawned == [tuple(missed.cmd), tuple(own.cmd)]
