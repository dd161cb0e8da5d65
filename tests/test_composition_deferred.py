"""Composable node loads written in timers and event handlers reach the LoadNode driver.

Pure: the supervisor runs real short-lived children and hands every LoadComponents step over
on its record stream (HandedOff) as it reaches it, from the plan, a TimerAction or an event
handler alike; a subscriber stands in for the driver. tests/test_composition_deferred_ros.py
sends them to real rclpy containers.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from test_supervision import Harness, plan_from, write_launch

from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.plan.records import HandedOff, Record, ShutdownBegun, Started
from mlaunch.plan.steps import Need, Plan

# A process that lives until the test's run is shut down, and one that exits at once.
DEFERRED = """
    from launch.actions import OpaqueFunction, RegisterEventHandler, TimerAction
    from launch.event_handlers import OnProcessExit, OnProcessStart
    from launch_ros.actions import LoadComposableNodes, PushROSNamespace
    from launch_ros.descriptions import ComposableNode


    def load(target, name):
        return LoadComposableNodes(
            target_container=target,
            composable_node_descriptions=[ComposableNode(package='p', plugin='p::N', name=name)],
        )


    def generate_launch_description():
        short = ExecuteProcess(cmd=[PY, '-c', 'pass'], name='short')
        return LaunchDescription([
            load('/top', 'top'),
            TimerAction(period=0.2, actions=[PushROSNamespace('t'), load('/timer', 'in_timer')]),
            RegisterEventHandler(OnProcessStart(target_action=short, on_start=[
                load('/start', 'on_start')])),
            RegisterEventHandler(OnProcessExit(target_action=short, on_exit=[
                OpaqueFunction(function=lambda context: [load('/exit', 'on_exit')])])),
            short,
        ])
"""


class Loads:
    """Takes the LoadComponents steps handed over (as the driver does) and shuts the run down
    once ``count`` of them came, so the run ends on the event, not on a clock."""

    def __init__(self, harness: Harness, count: int) -> None:
        self.harness = harness
        self.count = count
        self.steps: list[LoadComponents] = []
        self.order: list[str] = []
        harness.sup.records.subscribe(self.on_record)

    def on_record(self, record: Record) -> None:
        if isinstance(record, Started):
            self.order.append(f"started {record.process.spec.base_name}")
        if not isinstance(record, HandedOff) or not isinstance(record.step, LoadComponents):
            return
        record.taken = True
        self.steps.append(record.step)
        self.order.append(f"load {record.step.target}")
        if len(self.steps) == self.count:
            self.harness.sup.begin_shutdown("every load handed over")


def test_loads_in_timers_and_handlers_are_handed_over_in_launch_order(tmp_path: Path) -> None:
    plan = plan_from(write_launch(tmp_path, DEFERRED), tmp_path)
    # The timer's and the handlers' loads are not resolved yet; the driver is still needed.
    assert [s.target for s in plan.steps if isinstance(s, LoadComponents)] == ["/top"]
    assert Need.COMPONENTS in plan.needs
    h = Harness(plan)
    loads = Loads(h, 4)
    assert h.run() == 0
    assert loads.order[:3] == ["load /top", "started short", "load /start"]
    assert sorted(loads.order[3:]) == ["load /exit", "load /timer"]
    by_target = {s.target: s for s in loads.steps}
    # Resolved when they fired: the timer's pushed namespace applies to its own load.
    assert by_target["/timer"].requests[0].node_namespace == "/t"
    assert by_target["/exit"].requests[0].node_name == "on_exit"


def test_a_load_keeps_an_idle_launch_running_until_its_work_is_done() -> None:
    """Nothing runs, but a load is pending: no idle shutdown until the part says it is done
    (launch waits for LoadComposableNodes' completion futures the same way)."""
    step = LoadComponents("x.launch.py:1", "/elsewhere", ())
    h = Harness(Plan(steps=[step]))
    seen: list[str] = []
    work = object()

    def on_record(record: Record) -> None:
        if isinstance(record, HandedOff):
            record.taken = True
            h.sup.busy(work)
            h.sup.schedule(0.05, finish, keeps_alive=False)
        elif isinstance(record, ShutdownBegun):
            seen.append(f"shutdown {record.reason}")

    def finish() -> None:
        seen.append("done")
        h.sup.done(work)

    h.sup.records.subscribe(on_record)
    assert h.run() == 0
    assert seen == ["done", "shutdown idle"]


@pytest.mark.parametrize("suffix", ["xml", "yaml"])
def test_a_timer_tag_with_load_composable_node_is_handed_over(suffix: str, tmp_path: Path) -> None:
    body = {
        "xml": """
            <launch>
              <timer period="0.1">
                <push_ros_namespace namespace="t"/>
                <load_composable_node target="/box">
                  <composable_node pkg="p" plugin="p::N" name="in_timer"/>
                </load_composable_node>
              </timer>
            </launch>
        """,
        "yaml": """
            launch:
            - timer:
                period: 0.1
                children:
                - push_ros_namespace: {namespace: t}
                - load_composable_node:
                    target: /box
                    composable_node:
                    - {pkg: p, plugin: "p::N", name: in_timer}
        """,
    }[suffix]
    path = tmp_path / f"timer.launch.{suffix}"
    path.write_text(textwrap.dedent(body))
    plan = plan_from(path, tmp_path)
    assert Need.COMPONENTS in plan.needs
    h = Harness(plan)
    loads = Loads(h, 1)
    assert h.run() == 0
    (step,) = loads.steps
    assert step.target == "/box"
    assert [(r.node_name, r.node_namespace) for r in step.requests] == [("in_timer", "/t")]
