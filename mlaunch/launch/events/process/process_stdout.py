"""``launch.events.process.process_stdout``: a process wrote to its stdout."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.process.process_io import ProcessIO

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ProcessStdout(ProcessIO):
    """Text a process wrote to its stdout (fd 1)."""

    def __init__(self, *, text: bytes, **kwargs: Any) -> None:
        super().__init__(text=text, **{"fd": 1, **kwargs})
