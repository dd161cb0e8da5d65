"""``launch_testing`` of ROS 2, on mlaunch: integration tests of launches.

A test file defines ``generate_test_description()`` returning a LaunchDescription with a
``launch_testing.actions.ReadyToTest`` (and optionally a dictionary of values for the tests),
plus unittest TestCases: active ones run while the launch is up, ``@post_shutdown_test()``
ones after it ended. Run it with ``launch_test FILE`` or ``mlaunch test FILE``.
"""

from __future__ import annotations

from mlaunch.launch_testing import actions, asserts, markers, tools, util
from mlaunch.launch_testing.io_handler import ActiveIoHandler, IoHandler
from mlaunch.launch_testing.markers import (
    parametrize,
    post_shutdown_test,
    ready_to_test_action_timeout,
)
from mlaunch.launch_testing.proc_info_handler import ActiveProcInfoHandler, ProcInfoHandler

__all__ = [
    "ActiveIoHandler",
    "ActiveProcInfoHandler",
    "IoHandler",
    "ProcInfoHandler",
    "actions",
    "asserts",
    "markers",
    "parametrize",
    "post_shutdown_test",
    "ready_to_test_action_timeout",
    "tools",
    "util",
]
