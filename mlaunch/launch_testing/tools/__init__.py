"""``launch_testing.tools``: start a process from inside a test, and match its output."""

from __future__ import annotations

from mlaunch.launch_testing.tools.output import (
    basic_output_filter,
    expect_output,
    expected_output_from_file,
)
from mlaunch.launch_testing.tools.process import ProcessProxy, launch_process

__all__ = [
    "ProcessProxy",
    "basic_output_filter",
    "expect_output",
    "expected_output_from_file",
    "launch_process",
]
