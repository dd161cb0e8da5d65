"""``launch.events.process.signal_process``: signal the processes a matcher picks."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.process.process_targeted_event import ProcessTargetedEvent

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class SignalProcess(ProcessTargetedEvent):
    _fields = ("signal_number", "process_matcher")

    def __init__(
        self, signal_number: int = 2, process_matcher: ProcessMatcher | None = None
    ) -> None:
        super().__init__(process_matcher=process_matcher)
        self.signal_number = signal_number
