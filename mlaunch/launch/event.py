"""``launch.event``: ``Event``, the base of everything the supervisor announces or a launch
file emits.
"""

from __future__ import annotations

from collections.abc import Callable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class Event:
    """Base of everything the supervisor announces or a launch file emits."""

    name = "launch.Event"
