"""``launch.actions.opaque_function``: call launch-file code while resolving; visit what it
returns.
"""

from __future__ import annotations

from mlaunch.launch.action import Action

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class OpaqueFunction(Action):
    """Call ``function(context, *args, **kwargs)`` while resolving; visit what it returns."""

    def __init__(
        self,
        *,
        function: Callable[..., Any],
        args: Iterable[Any] | None = None,
        kwargs: dict[str, Any] | None = None,
        **action_kwargs: Any,
    ) -> None:
        super().__init__(**action_kwargs)
        self.function = function
        self.args = list(args or [])
        self.kwargs = dict(kwargs or {})

    def execute(self, context: LaunchContext) -> list[Any] | None:
        planner = context.planner
        result = planner.call_user(self.function, context, *self.args, **self.kwargs)
        return list(result) if result else None

    def describe_short(self) -> str:
        return f"OpaqueFunction({getattr(self.function, '__qualname__', self.function)!r})"
