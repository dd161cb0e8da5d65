"""``launch.actions.push_environment``: keep the environment, for the matching Pop to restore
(one scope of the context: see ``push_launch_configurations``).
"""

from __future__ import annotations

from mlaunch.launch.action import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PushEnvironment(Action):
    """Keep the environment as it is now (one scope of the context: see the module
    docstring)."""

    def execute(self, context: LaunchContext) -> None:
        context.push_scope()
