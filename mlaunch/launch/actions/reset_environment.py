"""``launch.actions.reset_environment``: the environment the launch started with."""

from __future__ import annotations

from mlaunch.launch.action import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class ResetEnvironment(Action):
    """Forget every change made to the environment (what a non-forwarding group starts with)."""

    def execute(self, context: LaunchContext) -> None:
        context.environment = dict(context.initial_environment)
