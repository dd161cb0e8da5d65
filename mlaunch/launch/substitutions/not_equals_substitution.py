"""``launch.substitutions.not_equals_substitution``: whether two values differ."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    describe,
)
from mlaunch.launch.substitutions.boolean_substitution import bool_text, to_bool
from mlaunch.launch.substitutions.equals_substitution import EqualsSubstitution

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class NotEqualsSubstitution(EqualsSubstitution):
    def perform(self, context: LaunchContext) -> str:
        return bool_text(not to_bool(super().perform(context), "not-equals"))

    def describe(self) -> str:
        return f"NotEquals({describe(self.left)}, {describe(self.right)})"
