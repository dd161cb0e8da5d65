"""``launch.events.execution_complete``: an action finished executing."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.event import Event
from mlaunch.plan.value import Value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ExecutionComplete(Value, Event):
    """An action finished executing: a process exited for good, a timer fired (or was cancelled).

    As in launch, it is only emitted for an action that a handler was waiting for when the
    action was visited.
    """

    name = "launch.events.ExecutionComplete"
    _fields = ("action",)

    def __init__(self, action: Any = None) -> None:
        self.action = action
