"""``launch.events.process.process_stderr``: a process wrote to its stderr."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.process.process_io import ProcessIO

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ProcessStderr(ProcessIO):
    """Text a process wrote to its stderr (fd 2, unless the caller says otherwise)."""

    def __init__(self, *, text: bytes, **kwargs: Any) -> None:
        super().__init__(text=text, **{"fd": 2, **kwargs})
