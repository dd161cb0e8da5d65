"""``launch.actions.pop_launch_configurations``: close the scope the matching Push opened."""

from __future__ import annotations

from mlaunch.launch.launch_description import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PopLaunchConfigurations(Action):
    """Restore the launch configurations the matching PushLaunchConfigurations kept."""

    def execute(self, context: LaunchContext) -> None:
        context.pop_scope()


__all__ = ["PopLaunchConfigurations"]
