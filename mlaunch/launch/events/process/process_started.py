"""``launch.events.process.process_started``: a process started."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.process.running_process_event import ProcessEvent

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ProcessStarted(ProcessEvent):
    pass
