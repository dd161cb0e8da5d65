"""``launch.actions.pop_environment``: restore the environment the matching Push kept (see
``push_launch_configurations``).
"""

from __future__ import annotations

from mlaunch.launch.action import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PopEnvironment(Action):
    """Restore the environment the matching PushEnvironment kept; the launch configurations
    stay as they are (see the module docstring)."""

    def execute(self, context: LaunchContext) -> None:
        configurations = context.launch_configurations
        context.pop_scope()
        context.launch_configurations = configurations
