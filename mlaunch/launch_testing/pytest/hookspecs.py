"""The hook launch_testing adds to pytest: which collector a launch test file gets.

launch_testing_ros implements it to run ROS-aware launch tests; launch_testing's own
implementation (tried last) gives a LaunchTestModule to files whose generate_test_description
is marked ``@pytest.mark.launch_test``.
"""

from __future__ import annotations

import pytest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


@pytest.hookspec(firstresult=True)
def pytest_launch_collect_makemodule(path: Any, parent: Any, entrypoint: Any) -> Any:
    """The collector of the launch test file ``path`` (``entrypoint`` is its
    generate_test_description), or None to leave it to the next implementation."""
