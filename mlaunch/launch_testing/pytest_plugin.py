"""The module mlaunch registers as pytest's ``launch_testing`` plugin (pyproject's pytest11).

The plugin lives at launch_testing's own path, ``mlaunch.launch_testing.pytest.hooks``; this
name stays so that an existing environment, whose entry point names it, keeps working.
"""

from __future__ import annotations

from mlaunch.launch_testing.pytest.hooks import (
    pytest_addhooks,
    pytest_addoption,
    pytest_configure,
    pytest_launch_collect_makemodule,
    pytest_pycollect_makemodule,
)

__all__ = [
    "pytest_addhooks",
    "pytest_addoption",
    "pytest_configure",
    "pytest_launch_collect_makemodule",
    "pytest_pycollect_makemodule",
]
