"""``launch.conditions.unless_condition``: visit the action when the expression is false."""

from __future__ import annotations

from mlaunch.launch.conditions.if_condition import IfCondition
from mlaunch.launch.substitution import describe

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class UnlessCondition(IfCondition):
    def evaluate(self, context: LaunchContext) -> bool:
        return not super().evaluate(context)

    def describe(self) -> str:
        return f"unless {describe(self.expression)}"
