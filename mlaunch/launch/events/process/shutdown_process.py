"""``launch.events.process.shutdown_process``: stop the processes a matcher picks."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.process.process_targeted_event import ProcessTargetedEvent

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ShutdownProcess(ProcessTargetedEvent):
    """Run the stop ladder on the processes the matcher selects."""

    name = "launch.events.process.ShutdownProcess"

    def __init__(self, process_matcher: ProcessMatcher | None = None) -> None:
        super().__init__(process_matcher=process_matcher)
