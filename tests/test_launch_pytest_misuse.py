"""launch_pytest reports misuse as ROS 2's does: a fixture returning no launch description, two
ReadyToTest, ``@pytest.mark.launch`` without ``fixture=``, a generator test marked
``shutdown=True``, a test yielding twice (each fails or errors, with launch_pytest's words)."""

from __future__ import annotations

from pathlib import Path

from procutil import clean_env
from test_launch_pytest import run_pytest

HEADER = """\
from launch import LaunchDescription
import launch_pytest
import pytest

"""

FUNCTION_SCOPE = (
    HEADER
    + """\
@launch_pytest.fixture
def not_a_description():
    return object()

@launch_pytest.fixture
def sequence_without_one():
    return [object, 'asd']

@launch_pytest.fixture
def two_ready():
    return LaunchDescription(
        [launch_pytest.actions.ReadyToTest(), launch_pytest.actions.ReadyToTest()]
    )

@launch_pytest.fixture
def good():
    return LaunchDescription([launch_pytest.actions.ReadyToTest()])

@pytest.mark.launch(fixture=not_a_description)
def test_object():
    pass

@pytest.mark.launch(fixture=sequence_without_one)
def test_sequence():
    pass

@pytest.mark.launch(fixture=two_ready)
def test_two_ready():
    pass

@pytest.mark.launch
def test_no_fixture():
    pass

@pytest.mark.launch(fixture=good, shutdown=True)
def test_generator_after_shutdown():
    yield

@pytest.mark.launch(fixture=good)
def test_yields_twice():
    yield
    yield

@pytest.mark.launch(fixture=good)
async def test_async_yields_twice():
    yield
    yield
"""
)

MODULE_SCOPE = (
    HEADER
    + """\
@launch_pytest.fixture(scope='module')
def shared():
    return LaunchDescription([launch_pytest.actions.ReadyToTest()])

@pytest.mark.launch(fixture=shared)
def test_yields_twice():
    yield
    yield
"""
)


def test_function_scoped_misuse_is_reported(tmp_path: Path) -> None:
    path = tmp_path / "test_misuse.py"
    path.write_text(FUNCTION_SCOPE)
    found, output = run_pytest(path, tmp_path, clean_env())
    assert found == [
        ["test_async_yields_twice", "failed"],
        ["test_generator_after_shutdown", "failed"],
        ["test_no_fixture", "skipped"],
        ["test_object", "error"],
        ["test_sequence", "error"],
        ["test_two_ready", "error"],
        ["test_yields_twice", "failed"],
    ], output
    for words in (
        "When running launch_pytest fixture 'not_a_description': return value must be either"
        " a launch description or a sequence which first item is a launch description",
        "fixture 'sequence_without_one': return value must be either a launch description",
        "must return a LaunchDescription containing only one ReadyToTest action",
        '"fixture" keyword argument is required in a pytest.mark.launch() decorator',
        "generator or async generator based launch test items cannot be marked with shutdown=True",
        "launch tests using a generator function must stop iteration after yielding once",
        "launch tests using an async gen function must stop iteration after yielding once",
    ):
        assert words in " ".join(output.split()), words


def test_a_wider_fixture_fails_the_shutdown_half_of_a_test_yielding_twice(
    tmp_path: Path,
) -> None:
    path = tmp_path / "test_module_scope.py"
    path.write_text(MODULE_SCOPE)
    found, output = run_pytest(path, tmp_path, clean_env())
    assert found == [["test_yields_twice", "failed"], ["test_yields_twice", "passed"]], output
    assert "must stop iteration after yielding once" in output
