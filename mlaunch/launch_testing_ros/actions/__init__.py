"""``launch_testing_ros.actions``, newer than Jazzy (ros2/launch_ros#459): EnableRmwIsolation."""

from __future__ import annotations

from mlaunch.launch_testing_ros.actions.enable_rmw_isolation import EnableRmwIsolation

__all__ = ["EnableRmwIsolation"]
