"""``launch.conditions.launch_configuration_equals``: visit the action when a launch
configuration has a value.
"""

from __future__ import annotations

from mlaunch.launch.condition import Condition
from mlaunch.launch.substitution import describe, normalize, perform_substitutions

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class LaunchConfigurationEquals(Condition):
    """The configuration equals the expected text; ``expected_value=None`` means it is unset."""

    def __init__(self, launch_configuration_name: str, expected_value: Any) -> None:
        import warnings

        warnings.warn(
            "The 'LaunchConfigurationEquals' and 'LaunchConfigurationNotEquals' Conditions are"
            " deprecated. Use the 'EqualsSubstitution' and 'NotEqualsSubstitution' substitutions"
            " instead! E.g.:\n  IfCondition(\n  \tEqualsSubstitution("
            "LaunchConfiguration('some_launch_arg'), \"some_equality_check\")\n  )",
            UserWarning,
            stacklevel=2,
        )
        super().__init__()
        self.name = launch_configuration_name
        self.expected = None if expected_value is None else normalize(expected_value)

    def _matches(self, context: LaunchContext) -> bool:
        value = context.launch_configurations.get(self.name)
        if self.expected is None:
            return value is None
        return value is not None and value == perform_substitutions(context, self.expected)

    def evaluate(self, context: LaunchContext) -> bool:
        return self._matches(context)

    def describe(self) -> str:
        return f"{self.name} == {describe(self.expected) if self.expected else 'unset'}"
