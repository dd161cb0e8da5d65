"""``launch.actions.unset_launch_configuration``: remove a launch configuration."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import normalize, perform_substitutions

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class UnsetLaunchConfiguration(Action):
    def __init__(self, name: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)

    def execute(self, context: LaunchContext) -> None:
        context.launch_configurations.pop(perform_substitutions(context, self.name), None)
