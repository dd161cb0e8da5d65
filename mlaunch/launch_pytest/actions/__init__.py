"""``launch_pytest.actions``: ReadyToTest, the same action as launch_testing's."""

from __future__ import annotations

from mlaunch.launch_testing.actions.ready import ReadyToTest

__all__ = ["ReadyToTest"]
