"""launch_testing's pytest plugin: ``pytest test_x.py`` runs a launch test file as one item.

A file whose ``generate_test_description`` carries ``@pytest.mark.launch_test`` is collected
through the ``pytest_launch_collect_makemodule`` hook (hookspecs.py); launch_testing's own
answer is a LaunchTestModule with one item that runs all of the file's launches and tests
(LaunchTestRunner) and fails listing every failed test. ``--launch-args a:=b ...`` passes
launch arguments.

The ROS 2 module names (``launch``, ``launch_testing`` ...) are served by mlaunch from the
first test module that imports one of them on, which launch_pytest's tests need as well.

Works with pytest 7.4 (what ROS 2 Jazzy runs on Ubuntu 24.04) and later: the one difference
that matters here is how a test module is imported (``import_kwargs``).
"""

from __future__ import annotations

import re

import pytest

from mlaunch.launch_testing.pytest import hookspecs

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path
    from typing import Any

_ROS_IMPORT = re.compile(
    rb"^\s*(?:import|from)\s+(?:launch|launch_ros|launch_testing|launch_testing_ros|launch_pytest)\b",
    re.MULTILINE,
)
_ENTRYPOINT = re.compile(rb"^(?:async\s+)?def\s+generate_test_description\b", re.MULTILINE)


def version_tuple(version: str) -> tuple[int, ...]:
    """``'8.1.0'`` -> (8, 1, 0); a pre-release or local suffix (``'9.0.0rc1'``) is dropped."""
    numbers = []
    for part in version.split("."):
        digits = re.match(r"\d+", part)
        if digits is None:
            break
        numbers.append(int(digits.group()))
        if digits.group() != part:
            break
    return tuple(numbers)


PYTEST_VERSION = version_tuple(pytest.__version__)


def import_kwargs(
    config: pytest.Config, version: tuple[int, ...] = PYTEST_VERSION
) -> dict[str, Any]:
    """The keywords of ``_pytest.pathlib.import_path`` for a test module, as pytest's own Module
    would pass them: ``consider_namespace_packages`` exists from pytest 8.1 on (7.4 refuses it)."""
    kwargs: dict[str, Any] = {"mode": config.getoption("importmode"), "root": config.rootpath}
    if version >= (8, 1):
        kwargs["consider_namespace_packages"] = config.getini("consider_namespace_packages")
    return kwargs


def import_test_module(path: Path, config: pytest.Config) -> Any:
    from _pytest.pathlib import import_path

    return import_path(path, **import_kwargs(config))


def pytest_addhooks(pluginmanager: Any) -> None:
    pluginmanager.add_hookspecs(hookspecs)


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--launch-args",
        action="append",
        nargs="*",
        default=[],
        help="launch arguments (name:=value) for launch_testing files",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "launch_test: mark a generate_test_description function as a launch test"
    )


def pytest_pycollect_makemodule(module_path: Path, parent: Any) -> Any:
    return collect_module(module_path, parent)


def collect_module(
    module_path: Path, parent: Any, serve_names: Callable[[], None] | None = None
) -> Any:
    """A LaunchTestModule for a launch test file, else None (pytest collects it itself).

    ``serve_names`` serves the ROS 2 module names from the first test module that imports one
    of them on (mlaunch.cli.pytest_launch_testing, the installed plugin, passes mlaunch's).
    """
    try:
        source = module_path.read_bytes()
    except OSError:
        return None
    if not _ROS_IMPORT.search(source):
        return None
    if serve_names is not None:
        serve_names()
    # Only files that may be launch tests are imported here (pytest imports the others itself).
    if not _ENTRYPOINT.search(source):
        return None
    entrypoint = getattr(
        import_test_module(module_path, parent.config), "generate_test_description", None
    )
    if entrypoint is None:
        return None
    ihook = parent.session.gethookproxy(module_path)
    return ihook.pytest_launch_collect_makemodule(
        path=module_path, parent=parent, entrypoint=entrypoint
    )


@pytest.hookimpl(trylast=True)
def pytest_launch_collect_makemodule(path: Path, parent: Any, entrypoint: Any) -> Any:
    if not any(mark.name == "launch_test" for mark in getattr(entrypoint, "pytestmark", [])):
        return None
    return LaunchTestModule.marked_as(entrypoint, parent=parent, path=path)


class LaunchTestFailure(Exception):
    """Some tests of a launch test file failed: ``results`` is {TestRun: result}."""

    def __init__(self, message: str, results: dict[Any, Any]) -> None:
        super().__init__(message)
        self.message = message
        self.results = results

    def failures(self) -> list[tuple[str, str]]:
        """(test id, formatted traceback) of every failed or erroring test."""
        return [
            (case.id(), text)
            for result in self.results.values()
            if not result.wasSuccessful()
            for case, text in result.errors + result.failures
        ]


class LaunchTestItem(pytest.Item):
    """Every launch and test of one launch_testing file."""

    test_runs: Any = None
    runner_cls: Any = None

    @classmethod
    def from_parent(  # type: ignore[override]
        cls, parent: Any, *, name: str, test_runs: Any, runner_cls: Any = None
    ) -> LaunchTestItem:
        from mlaunch.launch_testing.test_runner import LaunchTestRunner

        item: LaunchTestItem = super().from_parent(parent, name=name)
        item.test_runs = test_runs
        item.runner_cls = runner_cls or LaunchTestRunner
        return item

    def runtest(self) -> None:
        import copy

        arguments: list[str] = [
            a for group in self.config.getoption("--launch-args") for a in group
        ]
        # A copy per run: a plugin that reruns failed tests runs this item again.
        runner = self.runner_cls(
            copy.deepcopy(self.test_runs),
            launch_file_arguments=arguments,
            debug=bool(self.config.getoption("verbose")),
        )
        runner.validate()
        from mlaunch.ros.domain import Isolation

        with Isolation():  # a ROS domain of its own for the file, unless the user set one
            results = runner.run()
        if not all(r.wasSuccessful() for r in results.values()):
            raise LaunchTestFailure("some test cases have failed", results)

    def repr_failure(self, excinfo: Any, style: Any = None) -> Any:
        if isinstance(excinfo.value, LaunchTestFailure):
            return "\n\n".join(f"FAIL: {name}\n{text}" for name, text in excinfo.value.failures())
        return super().repr_failure(excinfo)

    def reportinfo(self) -> tuple[Any, int, str]:
        return self.path, 0, f"launch tests: {self.name}"


class LaunchTestModule(pytest.File):
    """A launch_testing file: imported once, collected as one LaunchTestItem."""

    @classmethod
    def marked_as(cls, entrypoint: Any, *, parent: Any, path: Path) -> LaunchTestModule:
        """The collector of ``path``, with the pytest marks of its generate_test_description."""
        module: LaunchTestModule = cls.from_parent(parent, path=path)
        for mark in getattr(entrypoint, "pytestmark", []):
            module.add_marker(getattr(pytest.mark, mark.name).with_args(*mark.args, **mark.kwargs))
        return module

    def makeitem(self, *, name: str, parent: Any, test_runs: Any) -> LaunchTestItem:
        return LaunchTestItem.from_parent(parent, name=name, test_runs=test_runs)

    def collect(self) -> Any:
        from mlaunch.launch_testing.loader import LoadTestsFromPythonModule

        module = import_test_module(self.path, self.config)
        yield self.makeitem(
            name=module.__name__,
            parent=self,
            test_runs=LoadTestsFromPythonModule(module, name=module.__name__),
        )
