"""``launch.actions.set_launch_configuration``: set a launch configuration for what follows."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import normalize, perform_substitutions

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class SetLaunchConfiguration(Action):
    """Set the configuration ``name`` to ``value``, both performed when it is visited."""

    def __init__(self, name: SomeSubstitutionsType, value: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)
        self.value = normalize(value)

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.name)
        context.launch_configurations[name] = perform_substitutions(context, self.value)
