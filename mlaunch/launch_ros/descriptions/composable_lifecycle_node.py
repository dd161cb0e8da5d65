"""``launch_ros.descriptions.composable_lifecycle_node``: ``ComposableLifecycleNode``, a
component whose node is a managed (lifecycle) node. Newer than Jazzy (launch_ros 0.29.3,
ros2/launch_ros#480); mlaunch runs it on Jazzy.

A ComposableNode plus ``autostart``: once its container has loaded it, the launch configures and
activates it, as a ``LifecycleNode(autostart=True)`` process is driven
(``mlaunch.parts.lifecycle``). Without ``autostart`` it is loaded as any component and left
unconfigured, as upstream leaves it.
"""

from __future__ import annotations

from mlaunch.launch_ros.descriptions.composable_node import ComposableNode
from mlaunch.plan.errors import LaunchFileTypeError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class ComposableLifecycleNode(ComposableNode):
    """A lifecycle component; ``autostart`` brings it to 'active' once it is loaded."""

    def __init__(self, *, autostart: Any = False, **kwargs: Any) -> None:
        from mlaunch.launch.utilities.type_utils import normalize_typed_substitution

        super().__init__(**kwargs)
        try:
            # A bool, or substitutions that give one when the node is loaded (as upstream).
            self.autostart = normalize_typed_substitution(autostart, bool)
        except TypeError:
            raise LaunchFileTypeError(
                f"autostart must be True, False or substitutions giving one, got"
                f" {type(autostart).__name__}: {autostart!r:.80}"
            ) from None

    @property
    def node_autostart(self) -> Any:
        """launch_ros's name for it."""
        return self.autostart

    def autostarts(self, context: LaunchContext) -> bool:
        """Whether the launch brings it up once loaded (its substitutions performed)."""
        from mlaunch.launch.utilities.type_utils import perform_typed_substitution

        try:
            return bool(perform_typed_substitution(context, self.autostart, bool))
        except (TypeError, ValueError) as e:
            raise LaunchFileTypeError(
                f"autostart of {self.describe_short()} must be true or false: {e}"
            ) from None

    def describe_short(self) -> str:
        text = super().describe_short()
        return text.replace("ComposableNode(", "ComposableLifecycleNode(", 1)
