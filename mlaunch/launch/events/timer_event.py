"""``launch.events.timer_event``: a TimerAction fired."""

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


class TimerEvent(Value, Event):
    """A TimerAction's period ran out (launch emits it, then visits the timer's actions)."""

    name = "launch.events.TimerEvent"
    _fields = ("timer_action",)

    def __init__(self, *, timer_action: Any) -> None:
        self.timer_action = timer_action
