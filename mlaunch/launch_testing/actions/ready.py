"""``launch_testing.actions.ready``: ReadyToTest, the action that starts the tests."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.plan.steps import StartTimer

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class ReadyToTest(Action):
    """Start the active tests once the actions before it have been carried out.

    It becomes a zero-delay timer of the plan: the supervisor fires it on the turn after it
    has started every process listed before it, which is when ROS 2 runs this action too (its
    processes are being started, not necessarily up yet; wait on their output in the tests).
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._callbacks: list[Callable[[], object]] = []

    def _add_callback(self, callback: Callable[[], object]) -> None:
        self._callbacks.append(callback)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        planner.add(
            StartTimer(
                origin=self.origin,
                period=0.0,
                body=planner.defer([], self.origin, callback=self._fire),
            )
        )

    def _fire(self, event: Any, context: Any) -> None:
        for callback in self._callbacks:
            callback()

    def describe_short(self) -> str:
        return "ReadyToTest()"


__all__ = ["ReadyToTest"]
