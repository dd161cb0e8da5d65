"""``launch.actions.pop_launch_configurations``: the configurations the matching Push kept."""

from __future__ import annotations

from mlaunch.launch.launch_description import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PopLaunchConfigurations(Action):
    """Restore the launch configurations the matching PushLaunchConfigurations kept; the
    environment stays as it is (see mlaunch.launch.actions.push_launch_configurations)."""

    def execute(self, context: LaunchContext) -> None:
        environment = context.environment
        context.pop_scope()
        context.environment = environment


__all__ = ["PopLaunchConfigurations"]
