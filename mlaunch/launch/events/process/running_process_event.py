"""``launch.events.process.running_process_event``: the base of the events of a running process.

Plain classes (not dataclasses, whose import and creation cost start-up time) that compare and
show themselves as dataclasses do, through ``mlaunch.plan.value.Value``.
"""

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


class ProcessEvent(Value, Event):
    """Fields of ROS 2's process events: the action, the label, argv, cwd, env and pid."""

    _fields: tuple[str, ...] = ("action", "name", "cmd", "cwd", "env", "pid")

    def __init__(
        self,
        action: Any = None,
        name: str = "",
        cmd: list[str] | None = None,
        cwd: str | None = None,
        env: dict[str, str] | None = None,
        pid: int = 0,
    ) -> None:
        self.action = action
        self.name = name
        self.cmd: list[str] = [] if cmd is None else cmd
        self.cwd = cwd
        self.env = env
        self.pid = pid

    # ROS 2's names for the same fields (launch_testing reads these).
    @property
    def process_name(self) -> str:
        return self.name

    @property
    def execute_process_action(self) -> Any:
        return self.action


# launch keeps the process events in the subpackage launch.events.process (also served
# from here, where the rest of mlaunch imports them).
RunningProcessEvent = ProcessEvent
