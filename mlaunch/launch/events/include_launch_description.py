"""``launch.events.include_launch_description``: a description to include, given as an event."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.event import Event

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class IncludeLaunchDescription(Event):
    """Include a description into the running launch (LaunchService, EmitEvent)."""

    name = "launch.events.IncludeLaunchDescription"

    def __init__(self, launch_description: Any) -> None:
        self.launch_description = launch_description
