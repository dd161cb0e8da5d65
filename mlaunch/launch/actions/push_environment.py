"""``launch.actions.push_environment``: keep the environment for the matching Pop."""

from __future__ import annotations

from mlaunch.launch.launch_description import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PushEnvironment(Action):
    """Keep the environment as it is now (one scope of the context, see
    mlaunch.launch.actions.push_launch_configurations)."""

    def execute(self, context: LaunchContext) -> None:
        context.push_scope()


__all__ = ["PushEnvironment"]
