"""``launch_pytest`` of ROS 2, on mlaunch: launches as pytest fixtures.

A ``@launch_pytest.fixture`` returns a LaunchDescription (or a tuple starting with one); tests
marked ``@pytest.mark.launch(fixture=that_fixture)`` run while it is up, those with
``shutdown=True`` after it was shut down, and a generator test's code after its ``yield`` runs
after the shutdown too. The plugin (mlaunch.launch_pytest.plugin) is registered with pytest
when mlaunch is installed.
"""

from __future__ import annotations

from mlaunch.launch_pytest import actions, tools
from mlaunch.launch_pytest.fixture import fixture

__all__ = ["actions", "fixture", "tools"]
