"""``launch.events.shutdown``: the launch is asked to shut down."""

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


class Shutdown(Value, Event):
    name = "launch.events.Shutdown"
    _fields = ("reason", "due_to_sigint")

    def __init__(self, reason: str = "reason not given", due_to_sigint: bool = False) -> None:
        self.reason = reason
        self.due_to_sigint = due_to_sigint
