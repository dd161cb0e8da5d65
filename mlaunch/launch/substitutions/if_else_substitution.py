"""``launch.substitutions.if_else_substitution``: one of two values, by a condition."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch.substitutions.boolean_substitution import to_bool

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class IfElseSubstitution(Substitution):
    """``if_value`` when the condition holds, else ``else_value``."""

    def __init__(
        self, condition: SomeSubstitutionsType, if_value: Any = "", else_value: Any = ""
    ) -> None:
        if if_value == else_value == "":
            # launch's error type and words (a RuntimeError, not a TypeError)
            raise RuntimeError("One of if_value and else_value must be specified")
        self.condition = normalize(condition)
        self.if_value = normalize(if_value)
        self.else_value = normalize(else_value)

    def perform(self, context: LaunchContext) -> str:
        # launch reads the condition as a typed bool (YAML's true/yes/on..., and 1/0)
        chosen = to_bool(perform_substitutions(context, self.condition), "IfElseSubstitution")
        return perform_substitutions(context, self.if_value if chosen else self.else_value)

    def describe(self) -> str:
        return (
            f"IfElse({describe(self.condition)}, {describe(self.if_value)},"
            f" {describe(self.else_value)})"
        )
