"""``launch.actions.pop_launch_configurations``: restore the launch configurations the matching
Push kept (see ``push_launch_configurations``).
"""

from __future__ import annotations

from mlaunch.launch.action import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PopLaunchConfigurations(Action):
    """Restore the launch configurations the matching PushLaunchConfigurations kept; the
    environment stays as it is (see the module docstring)."""

    def execute(self, context: LaunchContext) -> None:
        environment = dict(context.environment)  # a copy: a context on os.environ pops in place
        context.pop_scope()
        context.environment = environment
