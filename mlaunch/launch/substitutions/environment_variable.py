"""``launch.substitutions.environment_variable``: the value of an environment variable."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class EnvironmentVariable(Substitution):
    """An environment variable of the launch (``$(env NAME [default])``)."""

    def __init__(self, name: SomeSubstitutionsType, *, default_value: Any = None) -> None:
        self.name = normalize(name)
        self.default_value = None if default_value is None else normalize(default_value)

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        value = context.environment.get(name)
        if value is not None:
            return value
        if self.default_value is not None:
            return perform_substitutions(context, self.default_value)
        raise SubstitutionFailure(
            f"environment variable {name!r} does not exist: it is not set and has no default"
            " (give one: EnvironmentVariable(name, default_value=...) or $(env NAME default))"
        )

    def describe(self) -> str:
        return f"EnvVar({describe(self.name)})"
