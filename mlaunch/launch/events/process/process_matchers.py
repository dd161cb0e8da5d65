"""``launch.events.process.process_matchers``: matchers of a running process by pid, name or
executable.
"""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.matchers import _sees_process

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


def matches_pid(target_pid: int) -> ProcessMatcher:
    return _sees_process(lambda process: getattr(process, "pid", None) == target_pid)


def matches_name(target_name: str) -> ProcessMatcher:
    return _sees_process(lambda process: getattr(process, "label", None) == target_name)


def matches_executable(executable_name: str) -> ProcessMatcher:
    def match(process: Any) -> bool:
        argv: tuple[str, ...] = tuple(getattr(process, "argv", ()))
        return bool(argv) and argv[0].endswith(executable_name)

    return _sees_process(match)
