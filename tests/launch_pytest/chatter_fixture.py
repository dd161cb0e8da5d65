"""launch_pytest example written for mlaunch: a function-scoped launch of chatter.py, tests of
every kind (plain, generator, async, after shutdown) and one that must fail."""

import os
import sys

import launch
import launch.actions
import launch_pytest
import pytest
from launch_pytest.tools import process as process_tools

CHATTER = os.path.join(os.path.dirname(__file__), "..", "launch_testing", "chatter.py")


@pytest.fixture
def chatter():
    return launch.actions.ExecuteProcess(
        cmd=[sys.executable, CHATTER, "--count", "3", "--exit", "0", "pytest"],
        output="screen",
        cached_output=True,
    )


@launch_pytest.fixture
def launch_description(chatter):
    return launch.LaunchDescription([chatter, launch_pytest.actions.ReadyToTest()])


@pytest.mark.launch(fixture=launch_description)
def test_counts_then_says_goodbye(chatter, launch_context):
    def counted_to_two(output):
        assert "count 2" in output

    process_tools.assert_output_sync(launch_context, chatter, counted_to_two, timeout=10)
    assert process_tools.wait_for_exit_sync(launch_context, chatter, timeout=10)
    yield
    assert chatter.return_code == 0


@pytest.mark.launch(fixture=launch_description)
async def test_started(chatter, launch_context):
    assert await process_tools.wait_for_start(launch_context, chatter, timeout=10)


@pytest.mark.launch(fixture=launch_description, shutdown=True)
def test_after_shutdown(chatter, launch_service):
    assert launch_service._is_idle()
    assert chatter.return_code is not None


@pytest.mark.launch(fixture=launch_description)
def test_must_fail(chatter, launch_context):
    def never(output):
        assert "never printed" in output

    process_tools.assert_output_sync(launch_context, chatter, never, timeout=0.5)


@pytest.mark.launch(fixture=launch_description)
def test_a_false_validator_passes_an_assert(chatter, launch_context):
    # Only an AssertionError fails assert_output_sync; what the validator returns is ignored.
    process_tools.assert_output_sync(launch_context, chatter, lambda out: False, timeout=0.2)
