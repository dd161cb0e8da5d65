"""``launch.actions.timer_action``: resolve and run actions after a period."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import perform
from mlaunch.launch.substitutions.boolean_substitution import to_bool
from mlaunch.plan.steps import (
    StartTimer,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType
    from mlaunch.plan.steps import RosClock


class TimerAction(Action):
    """Resolve and run ``actions`` after ``period`` seconds (cancelled on shutdown by default)."""

    completes_later = True  # ExecutionComplete when it fires (the engine's timer)

    def __init__(
        self,
        *,
        period: float | SomeSubstitutionsType,
        actions: Iterable[Any],
        cancel_on_shutdown: Any = True,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.period = period
        self.actions = list(actions)
        self.cancel_on_shutdown = cancel_on_shutdown

    def get_sub_entities(self) -> list[Any]:
        return list(self.actions)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        period = planner.float_value(self.period, "TimerAction period", self.origin)
        cancel = self.cancel_on_shutdown
        if not isinstance(cancel, bool):
            cancel = to_bool(perform(context, cancel), "cancel_on_shutdown")
        planner.add(
            StartTimer(
                origin=self.origin,
                period=period,
                body=planner.defer(self.actions, self.origin),
                cancel_on_shutdown=cancel,
                action=self,
                ros_clock=self._ros_clock(context),
            )
        )

    def _ros_clock(self, context: LaunchContext) -> RosClock | None:
        """The clock the period is counted on: None, wall-clock time, as launch's TimerAction
        counts it (a ROSTimer's is the run's ROS clock)."""
        return None

    def describe_short(self) -> str:
        return f"TimerAction(period={self.period!r})"
