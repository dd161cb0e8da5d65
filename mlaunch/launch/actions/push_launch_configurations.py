"""``launch.actions.push_launch_configurations``: keep the launch configurations, for the
matching Pop to restore.

The stack of scopes: mlaunch's context keeps one stack, each entry the configurations and the
environment together (``LaunchContext.push_scope``). PushLaunchConfigurations and
PushEnvironment each push one; PopLaunchConfigurations takes the top one back for the
configurations only and PopEnvironment for the environment only, so each pair restores just its
own half, as upstream's two stacks do when pairs nest (a group returns them nested). Pairs that
cross (pushing one kind, then the other, and popping the first first) restore what the other
push kept.
"""

from __future__ import annotations

from mlaunch.launch.action import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PushLaunchConfigurations(Action):
    """Keep the launch configurations as they are now, for the matching Pop to restore."""

    def execute(self, context: LaunchContext) -> None:
        context.push_scope()
