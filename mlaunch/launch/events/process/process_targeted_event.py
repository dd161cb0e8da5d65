"""``launch.events.process.process_targeted_event``: the base of the events that act on the
processes a matcher picks.
"""

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


class ProcessTargetedEvent(Value, Event):
    """An event aimed at the running processes its matcher selects (launch's base class)."""

    name = "launch.events.process.ProcessTargetedEvent"
    _fields: tuple[str, ...] = ("process_matcher",)

    def __init__(self, *, process_matcher: ProcessMatcher | None = None) -> None:
        self.process_matcher = process_matcher
