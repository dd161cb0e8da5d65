"""``launch.events.process.process_exited``: a process exited."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.launch.events.process.running_process_event import ProcessEvent

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ProcessExited(ProcessEvent):
    _fields = (*ProcessEvent._fields, "returncode")

    def __init__(
        self,
        action: Any = None,
        name: str = "",
        cmd: list[str] | None = None,
        cwd: str | None = None,
        env: dict[str, str] | None = None,
        pid: int = 0,
        returncode: int = 0,
    ) -> None:
        super().__init__(action, name, cmd, cwd, env, pid)
        self.returncode = returncode
