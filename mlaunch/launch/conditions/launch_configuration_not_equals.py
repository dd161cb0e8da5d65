"""``launch.conditions.launch_configuration_not_equals``: visit the action when a launch
configuration has not a value.
"""

from __future__ import annotations

from mlaunch.launch.conditions.launch_configuration_equals import LaunchConfigurationEquals
from mlaunch.launch.substitution import describe

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class LaunchConfigurationNotEquals(LaunchConfigurationEquals):
    def evaluate(self, context: LaunchContext) -> bool:
        return not self._matches(context)

    def describe(self) -> str:
        return f"{self.name} != {describe(self.expected) if self.expected else 'unset'}"
