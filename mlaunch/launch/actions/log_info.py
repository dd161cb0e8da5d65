"""``launch.actions.log_info``: say a line when the plan reaches this point."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import normalize, perform_substitutions
from mlaunch.plan.steps import (
    Log,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class LogInfo(Action):
    def __init__(self, *, msg: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.msg = normalize(msg)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        planner.add(Log(origin=self.origin, message=perform_substitutions(context, self.msg)))
