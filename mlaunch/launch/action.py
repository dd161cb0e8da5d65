"""``launch.action``: ``Action``, the base of every action.

An action is data plus ``execute(context)``, upstream's contract: it reads the context, hands
what must happen at run time to ``context.planner`` as plan steps (mlaunch.plan.planner), and
may return entities to visit next. Nothing here starts a process or prints.
"""

from __future__ import annotations

from mlaunch.launch.event_handler import COMPLETION_HANDLERS
from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity
from mlaunch.plan.origin import caller_origin

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.condition import Condition
    from mlaunch.launch.launch_context import LaunchContext


class Action(LaunchDescriptionEntity):
    """Base of every action: an optional condition and where it was written."""

    def __init__(self, *, condition: Condition | None = None) -> None:
        self.condition = condition
        self.origin = caller_origin()

    # An action whose execution ends later than its visit (a process, a timer) says so itself.
    completes_later = False

    def visit(self, context: LaunchContext) -> list[Any] | None:
        if self.condition is not None and not self.condition.evaluate(context):
            return None
        more = self.execute(context)
        if not self.completes_later and context.run_state.get(COMPLETION_HANDLERS):
            # launch emits ExecutionComplete for every action once it has executed; only
            # when an OnExecutionComplete handler was registered may one be waiting for it.
            from mlaunch.launch.events.execution_complete import ExecutionComplete
            from mlaunch.plan.steps import EmitEvent

            event = ExecutionComplete(action=self)
            context.planner.add(EmitEvent(origin=self.origin, event=event))
        return more

    def execute(self, context: LaunchContext) -> list[Any] | None:
        return None

    def get_sub_entities(self) -> list[Any]:
        return []

    @staticmethod
    def parse(entity: Any, parser: Any) -> tuple[type[Action], dict[str, Any]]:
        """What every tag a package exposes shares (``launch.frontend``): its ``if`` or
        ``unless`` condition, as keyword arguments; subclasses' ``parse`` add their own."""
        from mlaunch.launch.conditions.if_condition import IfCondition
        from mlaunch.launch.conditions.unless_condition import UnlessCondition

        when = entity.get_attr("if", optional=True)
        unless = entity.get_attr("unless", optional=True)
        if when is not None and unless is not None:
            raise RuntimeError("if and unless conditions can't be used simultaneously")
        kwargs: dict[str, Any] = {}
        if when is not None:
            kwargs["condition"] = IfCondition(parser.parse_substitution(when))
        if unless is not None:
            kwargs["condition"] = UnlessCondition(parser.parse_substitution(unless))
        return Action, kwargs

    def describe(self) -> str:
        return repr(self)

    def describe_sub_entities(self) -> list[Any]:
        return self.get_sub_entities() if self.condition is None else []

    def describe_conditional_sub_entities(self) -> list[tuple[str, Iterable[Any]]]:
        if self.condition is None:
            return []
        return [(f"Conditionally included by {self.describe()}", self.get_sub_entities())]


def placed(actions: list[Action], origin: str) -> list[Action]:
    """``actions`` (made by a group or an include to scope what it holds) located where that
    was written: what an error in one of them names."""
    for action in actions:
        action.origin = origin
    return actions
