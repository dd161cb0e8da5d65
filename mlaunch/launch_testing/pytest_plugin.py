"""launch_testing's pytest plugin: ``pytest test_x.py`` runs a launch test file as one item.

A file whose ``generate_test_description`` carries ``@pytest.mark.launch_test`` is collected as
a LaunchTestModule with one item that runs all of its launches and tests (LaunchTestRunner)
and fails listing every failed test. ``--launch-args a:=b ...`` passes launch arguments.

It also serves the ROS 2 module names (``launch``, ``launch_testing`` ...) from the first test
module that imports one of them on, which launch_pytest's tests need as well.
"""

from __future__ import annotations

import re

import pytest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any

_ROS_IMPORT = re.compile(
    rb"^\s*(?:import|from)\s+(?:launch|launch_ros|launch_testing|launch_testing_ros|launch_pytest)\b",
    re.MULTILINE,
)
_LAUNCH_TEST_MARK = re.compile(rb"@pytest\.mark\.launch_test\b")


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
        "markers", "launch_test: generate_test_description of a launch_testing file"
    )


def pytest_pycollect_makemodule(module_path: Path, parent: Any) -> Any:
    try:
        source = module_path.read_bytes()
    except OSError:
        return None
    if not _ROS_IMPORT.search(source):
        return None
    from mlaunch import compat

    compat.install()
    if _LAUNCH_TEST_MARK.search(source) and b"generate_test_description" in source:
        return LaunchTestModule.from_parent(parent, path=module_path)
    return None


class LaunchTestFailure(Exception):
    """Some tests of a launch test file failed: ``failures`` is [(test id, traceback text)]."""

    def __init__(self, failures: list[tuple[str, str]]) -> None:
        super().__init__("some test cases have failed")
        self.failures = failures


class LaunchTestItem(pytest.Item):
    """Every launch and test of one launch_testing file."""

    def runtest(self) -> None:
        from mlaunch.launch_testing.loader import load_test_runs
        from mlaunch.launch_testing.test_runner import LaunchTestRunner

        module = self.parent.load()  # type: ignore[union-attr]
        runs = load_test_runs(module, name=module.__name__)
        arguments: list[str] = [
            a for group in self.config.getoption("--launch-args") for a in group
        ]
        runner = LaunchTestRunner(runs, launch_file_arguments=arguments)
        runner.validate()
        results = runner.run()
        failures = [
            (case.id(), text)
            for result in results.values()
            if not result.wasSuccessful()
            for case, text in result.errors + result.failures
        ]
        if failures or not all(r.wasSuccessful() for r in results.values()):
            raise LaunchTestFailure(failures)

    def repr_failure(self, excinfo: Any, style: Any = None) -> Any:
        if isinstance(excinfo.value, LaunchTestFailure):
            return "\n\n".join(f"FAIL: {name}\n{text}" for name, text in excinfo.value.failures)
        return super().repr_failure(excinfo)

    def reportinfo(self) -> tuple[Any, int, str]:
        return self.path, 0, f"launch tests: {self.name}"


class LaunchTestModule(pytest.File):
    """A launch_testing file: imported once, collected as one LaunchTestItem."""

    _module: Any = None

    def load(self) -> Any:
        if self._module is None:
            from _pytest.pathlib import import_path

            self._module = import_path(
                self.path, root=self.config.rootpath, consider_namespace_packages=False
            )
        return self._module

    def collect(self) -> Any:
        yield LaunchTestItem.from_parent(self, name=self.load().__name__)
