"""pytest's ``launch_testing`` plugin as installed (pyproject's pytest11 entry point).

launch_testing's own hooks (mlaunch.launch_testing.pytest.hooks), except that the collection
hook serves the ROS 2 module names (mlaunch.compat) from the first test module that imports one
of them on: this is the application's end of the plugin, the hooks know nothing above them.
"""

from __future__ import annotations

from mlaunch import compat
from mlaunch.launch_testing.pytest.hooks import (
    collect_module,
    pytest_addhooks,
    pytest_addoption,
    pytest_configure,
    pytest_launch_collect_makemodule,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any


def pytest_pycollect_makemodule(module_path: Path, parent: Any) -> Any:
    return collect_module(module_path, parent, serve_names=compat.install)


__all__ = [
    "pytest_addhooks",
    "pytest_addoption",
    "pytest_configure",
    "pytest_launch_collect_makemodule",
    "pytest_pycollect_makemodule",
]
