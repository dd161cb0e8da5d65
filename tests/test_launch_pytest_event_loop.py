"""launch_pytest's ``event_loop`` fixture: a launch test's coroutines run on it; any other test
gets a fresh loop."""

from __future__ import annotations

from pathlib import Path

from procutil import clean_env
from test_launch_pytest import run_pytest

TESTS = """\
import asyncio

from launch import LaunchDescription
import launch_pytest
import pytest


@launch_pytest.fixture
def described():
    return LaunchDescription([launch_pytest.actions.ReadyToTest()])


@pytest.mark.launch(fixture=described)
async def test_a_launch_test_runs_on_it(event_loop):
    assert asyncio.get_running_loop() is event_loop


@pytest.mark.launch(fixture=described)
def test_a_plain_launch_test_gets_the_same_kind(event_loop):
    assert isinstance(event_loop, asyncio.AbstractEventLoop) and not event_loop.is_closed()


def test_any_other_test_gets_a_fresh_one(event_loop):
    assert event_loop.run_until_complete(asyncio.sleep(0, result=3)) == 3
"""


def test_event_loop_fixture(tmp_path: Path) -> None:
    path = tmp_path / "test_loops.py"
    path.write_text(TESTS)
    found, output = run_pytest(path, tmp_path, clean_env())
    assert found == [
        ["test_a_launch_test_runs_on_it", "passed"],
        ["test_a_plain_launch_test_gets_the_same_kind", "passed"],
        ["test_any_other_test_gets_a_fresh_one", "passed"],
    ], output
