"""``EnableRmwIsolation()``: the launch's ROS traffic kept from every other run's.

launch_testing_ros has it after Jazzy (ros2/launch_ros#459), through rmw_test_fixture; a Jazzy
user copies it from a newer test. mlaunch accepts it on Jazzy and does what its own test
runners do (mlaunch.ros.domain): the processes started after it get a ROS domain no other run
holds, with discovery on this machine, and the test's own ROS objects (WaitForTopics) the same,
through ``os.environ``. When the run already has a domain of its own, that one is kept. The
claim lasts until the launch shuts down.
"""

from __future__ import annotations

import os
from typing import Any

from mlaunch.launch.action import Action
from mlaunch.launch.event_handlers.on_shutdown import OnShutdown
from mlaunch.ros import domain


class EnableRmwIsolation(Action):
    """Isolate the ROS communication of what the launch starts after this action."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.claim: domain.DomainClaim | None = None

    def execute(self, context: Any) -> None:
        if domain.held(context.environment.get("ROS_DOMAIN_ID", "")):
            return  # the run's own domain (mlaunch test, launch_test) is isolated already
        self.claim = domain.claim()
        values = {"ROS_DOMAIN_ID": str(self.claim.domain)}
        if "ROS_LOCALHOST_ONLY" not in context.environment:
            values["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        context.environment.update(values)
        if context.environment is not os.environ:
            os.environ.update(values)  # the test's own nodes, in this process, join it
        context.register_event_handler(OnShutdown(on_shutdown=self._release))

    def _release(self, event: Any, context: Any) -> None:
        if self.claim is not None:
            self.claim.release()
            self.claim = None
