"""``launch_testing`` of ROS 2, on mlaunch: integration tests of launches.

A test file defines ``generate_test_description()`` returning a LaunchDescription with a
``launch_testing.actions.ReadyToTest`` (and optionally a dictionary of values for the tests),
plus unittest TestCases: active ones run while the launch is up, ``@post_shutdown_test()``
ones after it ended. Run it with ``launch_test FILE``, ``mlaunch test FILE`` or pytest (the
file's generate_test_description marked ``@pytest.mark.launch_test``).
"""

from __future__ import annotations

from mlaunch.launch_testing import tools
from mlaunch.launch_testing.decorator import post_shutdown_test
from mlaunch.launch_testing.io_handler import ActiveIoHandler, IoHandler
from mlaunch.launch_testing.parametrize import parametrize
from mlaunch.launch_testing.proc_info_handler import ActiveProcInfoHandler, ProcInfoHandler
from mlaunch.launch_testing.ready_aggregator import ReadyAggregator
from mlaunch.launch_testing.ready_to_test_action_timeout import ready_to_test_action_timeout

__all__ = [
    "ActiveIoHandler",
    "ActiveProcInfoHandler",
    "IoHandler",
    "ProcInfoHandler",
    "ReadyAggregator",
    "parametrize",
    "post_shutdown_test",
    "ready_to_test_action_timeout",
    "tools",
]
