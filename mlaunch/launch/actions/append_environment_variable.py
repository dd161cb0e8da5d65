"""``launch.actions.append_environment_variable``: add a value to an environment variable (after
or before what it holds).
"""

from __future__ import annotations

import os

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import normalize, perform, perform_substitutions
from mlaunch.launch.substitutions.boolean_substitution import to_bool

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class AppendEnvironmentVariable(Action):
    def __init__(
        self,
        name: SomeSubstitutionsType,
        value: SomeSubstitutionsType,
        prepend: Any = False,
        separator: SomeSubstitutionsType = os.pathsep,
        **kwargs: Any,
    ):
        super().__init__(**kwargs)
        self.name = normalize(name)
        self.value = normalize(value)
        self.prepend = prepend
        self.separator = normalize(separator)

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.name)
        value = perform_substitutions(context, self.value)
        prepend = (
            self.prepend
            if isinstance(self.prepend, bool)
            else to_bool(perform(context, self.prepend), "prepend")
        )
        old = context.environment.get(name)
        sep = perform_substitutions(context, self.separator)
        if not old:
            context.environment[name] = value
        else:
            context.environment[name] = f"{value}{sep}{old}" if prepend else f"{old}{sep}{value}"
