"""launch_testing_ros's pytest plugin: a launch test file whose generate_test_description is
marked ``@pytest.mark.rostest`` runs with launch_testing_ros's LaunchTestRunner.

It answers launch_testing's ``pytest_launch_collect_makemodule`` hook (hookspecs.py there)
before launch_testing's own answer, which takes ``@pytest.mark.launch_test`` files.
"""

from __future__ import annotations

import pytest

from mlaunch.launch_testing.pytest.hooks import LaunchTestItem, LaunchTestModule

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any


class LaunchROSTestItem(LaunchTestItem):
    """A launch test file's launches and tests, run by launch_testing_ros's runner."""

    @classmethod
    def from_parent(  # type: ignore[override]
        cls, parent: Any, *, name: str, test_runs: Any, runner_cls: Any = None
    ) -> LaunchTestItem:
        from mlaunch.launch_testing_ros.test_runner import LaunchTestRunner

        return super().from_parent(
            parent, name=name, test_runs=test_runs, runner_cls=runner_cls or LaunchTestRunner
        )


class LaunchROSTestModule(LaunchTestModule):
    """A launch test file marked ``rostest``."""

    def makeitem(self, *, name: str, parent: Any, test_runs: Any) -> LaunchTestItem:
        return LaunchROSTestItem.from_parent(parent, name=name, test_runs=test_runs)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "rostest: mark a generate_test_description function as a ROS launch test entrypoint",
    )


def pytest_launch_collect_makemodule(path: Path, parent: Any, entrypoint: Any) -> Any:
    if not any(mark.name == "rostest" for mark in getattr(entrypoint, "pytestmark", [])):
        return None
    return LaunchROSTestModule.marked_as(entrypoint, parent=parent, path=path)
