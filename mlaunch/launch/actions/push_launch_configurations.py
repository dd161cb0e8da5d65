"""``launch.actions.push_launch_configurations``: open a scope (what GroupAction returns first).

mlaunch's context keeps one stack of scopes for the configurations and the environment together
(``LaunchContext.push_scope``): PushLaunchConfigurations and PushEnvironment each push one, and
their Pop counterparts each restore one, so a pair opened and closed in order (a group, a
scoped include) leaves both as they were.
"""

from __future__ import annotations

from mlaunch.launch.launch_description import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PushLaunchConfigurations(Action):
    """Keep the launch configurations as they are now, for the matching Pop to restore."""

    def execute(self, context: LaunchContext) -> None:
        context.push_scope()


__all__ = ["PushLaunchConfigurations"]
