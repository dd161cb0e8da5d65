"""Event handlers of no kind the engine dispatches itself: ``EventHandler(matcher=...)`` and
handlers of extensions register, and their ``matches(event)`` decides for every event of the
run, as every handler of launch's does (the general path)."""

from __future__ import annotations

from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

from mlaunch.launch.actions import (
    Action,
    LogInfo,
    RegisterEventHandler,
    UnregisterEventHandler,
)
from mlaunch.launch.event_handlers import MATCHER_KIND, EventHandler
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.planning import StandalonePlanner
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import AddHandler, RemoveHandler


def test_a_handler_with_a_matcher_registers_and_unregisters_once() -> None:
    context = LaunchContext()
    handler = EventHandler(matcher=lambda event: True, entities=[LogInfo(msg="x")])
    RegisterEventHandler(handler).visit(context)
    assert context.would_handle_event(object())
    UnregisterEventHandler(handler).visit(context)
    assert not context.would_handle_event(object())
    with pytest.raises(ValueError, match="not registered"):
        UnregisterEventHandler(handler).visit(context)
    planner = context.planner
    assert isinstance(planner, StandalonePlanner)
    steps = planner.plan.steps
    added, removed = [s for s in steps if isinstance(s, (AddHandler, RemoveHandler))]
    assert isinstance(added, AddHandler) and added.kind == MATCHER_KIND
    assert added.handler is handler and added.matcher is None
    assert isinstance(removed, RemoveHandler) and removed.handler is handler


def test_what_is_no_event_handler_is_refused_where_registered() -> None:
    with pytest.raises(LaunchFileError, match="not an event handler"):
        RegisterEventHandler(object()).visit(LaunchContext())


def test_the_handlers_entities_are_described_as_conditional() -> None:
    inside, outside = Action(), Action()
    register = RegisterEventHandler(EventHandler(matcher=lambda e: True, entities=[inside]))
    assert register.describe_sub_entities() == []
    ((text, entities),) = register.describe_conditional_sub_entities()
    assert text.startswith("EventHandler(") and inside in entities and outside not in entities
    assert (
        RegisterEventHandler(
            EventHandler(matcher=lambda e: True)
        ).describe_conditional_sub_entities()
        == []
    )


GENERAL = """\
import sys
from launch import EventHandler, LaunchDescription
from launch.actions import EmitEvent, ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event import Event
from launch.events.process import ProcessExited

class Ping(Event):
    name = 'test.Ping'

class Counting(EventHandler):
    def __init__(self):
        super().__init__(matcher=lambda event: isinstance(event, Ping))

    def handle(self, event, context):
        return [LogInfo(msg='own handle saw ' + type(event).__name__)]

def generate_launch_description():
    return LaunchDescription([
        RegisterEventHandler(EventHandler(
            matcher=lambda event: isinstance(event, Ping),
            entities=[LogInfo(msg='ping handled')])),
        RegisterEventHandler(EventHandler(
            matcher=lambda event: isinstance(event, ProcessExited) and event.returncode == 3,
            entities=[LogInfo(msg='exit 3 handled')], handle_once=True)),
        RegisterEventHandler(Counting()),
        EmitEvent(event=Ping()),
        ExecuteProcess(cmd=[sys.executable, '-c', 'raise SystemExit(3)']),
    ])
"""


def test_a_run_fires_handlers_whose_matcher_accepts_the_event(tmp_path: Path) -> None:
    path = tmp_path / "general.launch.py"
    path.write_text(GENERAL)
    done = run_mlaunch(str(path), env=clean_env())
    said = [line.split("]: ", 1)[1] for line in done.stdout.splitlines() if "launch.user" in line]
    assert sorted(said) == ["exit 3 handled", "own handle saw Ping", "ping handled"], (
        done.stdout + done.stderr
    )


RAISING = """\
from launch import EventHandler, LaunchDescription
from launch.actions import EmitEvent, RegisterEventHandler
from launch.event import Event

class Ping(Event):
    name = 'test.Ping'

def generate_launch_description():
    return LaunchDescription([
        RegisterEventHandler(EventHandler(matcher=lambda: True)),
        EmitEvent(event=Ping()),
    ])
"""


def test_a_matcher_that_raises_is_said_where_it_was_written(tmp_path: Path) -> None:
    path = tmp_path / "raising.launch.py"
    path.write_text(RAISING)
    done = run_mlaunch(str(path), env=clean_env())
    said = done.stdout + done.stderr
    assert done.returncode == 2, said
    failed = [
        line for line in said.splitlines() if "the matcher of an event handler failed" in line
    ]
    assert len(failed) == 1, said  # said once: the handler is dropped
    assert f"{path}:10:" in failed[0] and "TypeError" in failed[0]
