"""``launch_ros.events.matchers.matches_node_name``: the matcher of a lifecycle node by its name."""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch_ros.events.lifecycle.change_state import LifecycleNodeMatcher


def matches_node_name(node_name: str) -> LifecycleNodeMatcher:
    """A matcher for the lifecycle node with this full name (a Node action or a ProcessSpec);
    a name without the leading '/' is taken from the root, as launch_ros does."""
    if not node_name.startswith("/"):
        node_name = "/" + node_name
    return _NodeNamed(node_name)


class _NodeNamed:
    """The matcher ``matches_node_name`` returns (a class, not a closure: a plan that holds it
    can be stored in the plan cache)."""

    __slots__ = ("node_name",)

    def __init__(self, node_name: str) -> None:
        self.node_name = node_name

    def __call__(self, target: Any) -> bool:
        info = getattr(target, "node", None)  # a ProcessSpec carries NodeInfo
        if info is not None and hasattr(info, "fully_qualified_name"):
            return bool(info.fully_qualified_name == self.node_name)
        try:
            return bool(getattr(target, "node_name", None) == self.node_name)
        except RuntimeError:  # a Node not resolved yet has no name
            return False
