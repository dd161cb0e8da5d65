"""``launch.substitutions.launch_configuration``: the value of a launch configuration."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Path,
    SomeSubstitutionsType,
    Subs,
    Substitution,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class LaunchConfiguration(Substitution):
    """The value of a launch configuration (an argument or a ``let``), with an optional default."""

    def __init__(self, variable_name: SomeSubstitutionsType, *, default: Any = None) -> None:
        self.variable_name = normalize(variable_name)
        if default is None:
            self.default: Subs | None = None
        elif isinstance(default, (str, Substitution, Path, list, tuple)):
            self.default = normalize(default)
        else:
            self.default = normalize(str(default))

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.variable_name)
        configs = context.launch_configurations
        if name in configs:
            value = configs[name]
            return value if isinstance(value, str) else str(value)
        if self.default is not None:
            return perform_substitutions(context, self.default)
        from mlaunch.plan.errors import did_you_mean

        hint = did_you_mean(name, (k for k in configs if isinstance(k, str)))
        raise SubstitutionFailure(f"launch configuration {name!r} does not exist{hint}")

    def describe(self) -> str:
        name = "".join(s.describe().strip("'") for s in self.variable_name)
        return f"LaunchConfig({name!r})"
