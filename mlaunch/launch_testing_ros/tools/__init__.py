"""``launch_testing_ros.tools``: basic_output_filter, knowing RMW implementations' own lines."""

from __future__ import annotations

from mlaunch.launch_testing_ros.tools.output import basic_output_filter

__all__ = ["basic_output_filter"]
