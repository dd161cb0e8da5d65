"""launch_testing pieces that run a launch or sit in pytest: StdoutReadyListener on a real
launch, and the plugins' pytest-version-dependent paths (7.4, what ROS 2 Jazzy runs on Ubuntu
24.04, and the venv's current pytest): importing a test module, reading a fixture's marker."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import (
    ExecuteProcess,
    LaunchDescription,
    OpaqueFunction,
    RegisterEventHandler,
)
from mlaunch.launch_pytest.plugin import fixture_marker
from mlaunch.launch_testing.event_handlers import StdoutReadyListener
from mlaunch.launch_testing.pytest import hooks
from mlaunch.launch_testing.util import KeepAliveProc

READY_THEN_EXIT = "print('warming up', flush=True)\nprint('Ready', flush=True)"


def _run_with_listener(ready_txt: str, *, target: ExecuteProcess | None) -> list[str]:
    """Run a process that prints 'Ready' and exits, with a listener for ``ready_txt``."""
    seen: list[str] = []
    process = ExecuteProcess(cmd=[sys.executable, "-c", READY_THEN_EXIT])
    listener = StdoutReadyListener(
        target_action=process if target is None else target,
        ready_txt=ready_txt,
        actions=[OpaqueFunction(function=lambda context: seen.append("ready"))],
    )
    service = LaunchService(screen=lambda data: None)
    service.include_launch_description(LaunchDescription([process, RegisterEventHandler(listener)]))
    assert service.run() == 0
    return seen


def test_stdout_ready_listener_runs_its_actions_on_the_text() -> None:
    assert _run_with_listener("Ready", target=None) == ["ready"]


def test_stdout_ready_listener_ignores_other_text_and_other_processes() -> None:
    assert _run_with_listener("not_ready", target=None) == []
    assert _run_with_listener("Ready", target=KeepAliveProc()) == []


def test_stdout_ready_listener_describes_the_actions_it_runs() -> None:
    action = OpaqueFunction(function=lambda context: None)
    listener = StdoutReadyListener(ready_txt="x", actions=[action])
    assert listener.describe()[1] == [action]


@pytest.mark.parametrize(
    ("text", "expected"),
    [("7.4.4", (7, 4, 4)), ("8.1.0", (8, 1, 0)), ("9.0.0rc1", (9, 0, 0)), ("8.2.dev3", (8, 2))],
)
def test_pytest_versions_are_read_as_numbers(text: str, expected: tuple[int, ...]) -> None:
    assert hooks.version_tuple(text) == expected


class _Config:
    """What import_kwargs reads of a pytest config, as any pytest version has it."""

    rootpath = Path("/somewhere")

    def getoption(self, name: str) -> str:
        assert name == "importmode"
        return "prepend"

    def getini(self, name: str) -> bool:
        assert name == "consider_namespace_packages"  # an ini only pytest >= 8.1 knows
        return False


def test_import_keywords_follow_the_pytest_version(pytestconfig: pytest.Config) -> None:
    # pytest 7.4's import_path refuses consider_namespace_packages (added in 8.1): every
    # @pytest.mark.launch_test file failed to collect there.
    config: Any = _Config()
    assert hooks.import_kwargs(config, (7, 4, 4)) == {"mode": "prepend", "root": config.rootpath}
    assert hooks.import_kwargs(config, (8, 1, 0)) == {
        "mode": "prepend",
        "root": config.rootpath,
        "consider_namespace_packages": False,
    }
    current = hooks.import_kwargs(pytestconfig)  # the running pytest: its own keywords
    assert ("consider_namespace_packages" in current) == (pytest.version_tuple >= (8, 1))


def test_the_current_pytest_imports_a_test_module_with_those_keywords(
    pytestconfig: pytest.Config, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "launch_thing_test.py"
    path.write_text("def generate_test_description():\n    return 'described'\n")
    monkeypatch.syspath_prepend(str(tmp_path))  # undone after the test, as the import's entry
    module = hooks.import_test_module(path, pytestconfig)
    assert module.generate_test_description() == "described"
    monkeypatch.delitem(sys.modules, module.__name__)


class _Marker:
    def __init__(self, scope: str, name: str | None = None) -> None:
        self.scope = scope
        self.name = name


def test_a_fixture_marker_is_found_where_each_pytest_keeps_it() -> None:
    def pytest_7_4_fixture() -> None:  # the function itself, marked (up to pytest 8.3)
        return None

    pytest_7_4_fixture._pytestfixturefunction = _Marker("module")  # type: ignore[attr-defined]

    class Pytest84Definition:  # a FixtureFunctionDefinition (pytest 8.4 on)
        _fixture_function_marker = _Marker("class", "renamed")

    assert fixture_marker(pytest_7_4_fixture).scope == "module"
    assert fixture_marker(Pytest84Definition()).name == "renamed"
    assert fixture_marker(lambda: None) is None

    @pytest.fixture(scope="session")
    def real() -> None:
        return None

    assert fixture_marker(real).scope == "session"  # whichever pytest runs this
