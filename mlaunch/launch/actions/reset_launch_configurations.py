"""``launch.actions.reset_launch_configurations``: clear the launch configurations, keeping
those given.
"""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import perform

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class ResetLaunchConfigurations(Action):
    """Forget every configuration, then set the given ones (performed before forgetting)."""

    def __init__(self, launch_configurations: dict[Any, Any] | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.launch_configurations = launch_configurations or {}

    def execute(self, context: LaunchContext) -> None:
        keep = {
            perform(context, k): perform(context, v) for k, v in self.launch_configurations.items()
        }
        context.launch_configurations = keep
