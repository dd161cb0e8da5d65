"""``launch_testing_ros.LaunchTestRunner``: the runner ROS launch tests run with (``rostest``)."""

from __future__ import annotations

from mlaunch.launch_testing import test_runner


class LaunchTestRunner(test_runner.LaunchTestRunner):
    """launch_testing's runner; its own class, so ROS tests can be told apart and extended."""


__all__ = ["LaunchTestRunner"]
