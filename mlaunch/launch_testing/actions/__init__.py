"""``launch_testing.actions``: ReadyToTest, the action that tells the runner to start the tests."""

from __future__ import annotations

from mlaunch.launch_testing.actions.ready import ReadyToTest

__all__ = ["ReadyToTest"]
