"""``launch.condition``: ``Condition``, a predicate over the launch context that decides
whether an action is visited.
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class Condition:
    """A predicate over the launch context."""

    def __init__(self, *, predicate: Callable[[Any], bool] | None = None) -> None:
        self._predicate = predicate

    def evaluate(self, context: LaunchContext) -> bool:
        """The predicate's answer; False without a predicate, as launch."""
        if self._predicate is None:
            return False
        return bool(self._predicate(context))

    def describe(self) -> str:
        return type(self).__name__
