"""Events, with the names of ROS 2 launch, and the matchers handlers use to pick processes.

Plain classes (not dataclasses, whose import and creation cost start-up time) that compare and
show themselves as dataclasses do, through ``mlaunch.plan.record.Record``.
"""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.plan.record import Record

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class Event:
    """Base of everything the supervisor announces or a launch file emits."""

    name = "launch.Event"


class Shutdown(Record, Event):
    name = "launch.events.Shutdown"
    _fields = ("reason", "due_to_sigint")

    def __init__(self, reason: str = "reason not given", due_to_sigint: bool = False) -> None:
        self.reason = reason
        self.due_to_sigint = due_to_sigint


class ExecutionComplete(Record, Event):
    """An action finished executing: a process exited for good, a timer fired (or was cancelled).

    As in launch, it is only emitted for an action that a handler was waiting for when the
    action was visited.
    """

    name = "launch.events.ExecutionComplete"
    _fields = ("action",)

    def __init__(self, action: Any = None) -> None:
        self.action = action


class TimerEvent(Record, Event):
    """A TimerAction's period ran out (launch emits it, then visits the timer's actions)."""

    name = "launch.events.TimerEvent"
    _fields = ("timer_action",)

    def __init__(self, *, timer_action: Any) -> None:
        self.timer_action = timer_action


class ProcessEvent(Record, Event):
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


class ProcessStarted(ProcessEvent):
    pass


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


class ProcessIO(ProcessEvent):
    _fields = (*ProcessEvent._fields, "text", "fd")

    def __init__(
        self,
        action: Any = None,
        name: str = "",
        cmd: list[str] | None = None,
        cwd: str | None = None,
        env: dict[str, str] | None = None,
        pid: int = 0,
        text: bytes = b"",
        fd: int = 1,
    ) -> None:
        super().__init__(action, name, cmd, cwd, env, pid)
        self.text = text
        self.fd = fd

    @property
    def from_stdout(self) -> bool:
        return self.fd == 1

    @property
    def from_stderr(self) -> bool:
        return self.fd == 2


class ProcessStdin(ProcessIO):
    """Text written to a process's stdin (fd 0), as launch names it."""

    def __init__(self, *, text: bytes, **kwargs: Any) -> None:
        super().__init__(text=text, fd=0, **kwargs)


class ProcessStdout(ProcessIO):
    """Text a process wrote to its stdout (fd 1)."""

    def __init__(self, *, text: bytes, **kwargs: Any) -> None:
        super().__init__(text=text, **{"fd": 1, **kwargs})


class ProcessStderr(ProcessIO):
    """Text a process wrote to its stderr (fd 2, unless the caller says otherwise)."""

    def __init__(self, *, text: bytes, **kwargs: Any) -> None:
        super().__init__(text=text, **{"fd": 2, **kwargs})


class IncludeLaunchDescription(Event):
    """Include a description into the running launch (LaunchService, EmitEvent)."""

    name = "launch.events.IncludeLaunchDescription"

    def __init__(self, launch_description: Any) -> None:
        self.launch_description = launch_description


if TYPE_CHECKING:
    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


class ProcessTargetedEvent(Record, Event):
    """An event aimed at the running processes its matcher selects (launch's base class)."""

    name = "launch.events.process.ProcessTargetedEvent"
    _fields: tuple[str, ...] = ("process_matcher",)

    def __init__(self, *, process_matcher: ProcessMatcher | None = None) -> None:
        self.process_matcher = process_matcher


class ShutdownProcess(ProcessTargetedEvent):
    """Run the stop ladder on the processes the matcher selects."""

    name = "launch.events.process.ShutdownProcess"

    def __init__(self, process_matcher: ProcessMatcher | None = None) -> None:
        super().__init__(process_matcher=process_matcher)


class SignalProcess(ProcessTargetedEvent):
    _fields = ("signal_number", "process_matcher")

    def __init__(
        self, signal_number: int = 2, process_matcher: ProcessMatcher | None = None
    ) -> None:
        super().__init__(process_matcher=process_matcher)
        self.signal_number = signal_number


# A process matcher written in a launch file is given a running process's action, as launch's
# (``lambda action: action is talker``). The matchers below are given the running process
# itself (its action, pid, label and argv: an action may run more than one process here).
SEES_PROCESS = "sees_process"


def _sees_process(match: ProcessMatcher) -> ProcessMatcher:
    setattr(match, SEES_PROCESS, True)
    return match


def matches_action(target_action: Any) -> ProcessMatcher:
    return _sees_process(lambda process: getattr(process, "action", None) is target_action)


def matches_pid(target_pid: int) -> ProcessMatcher:
    return _sees_process(lambda process: getattr(process, "pid", None) == target_pid)


def matches_name(target_name: str) -> ProcessMatcher:
    return _sees_process(lambda process: getattr(process, "label", None) == target_name)


def matches_executable(executable_name: str) -> ProcessMatcher:
    def match(process: Any) -> bool:
        argv: tuple[str, ...] = tuple(getattr(process, "argv", ()))
        return bool(argv) and argv[0].endswith(executable_name)

    return _sees_process(match)


# launch keeps the process events in the subpackage launch.events.process (also served
# from here, where the rest of mlaunch imports them).
RunningProcessEvent = ProcessEvent


def __getattr__(name: str) -> Any:
    # ``launch.events.process`` loads on first use (it imports the names above).
    if name == "process":
        import importlib

        return importlib.import_module("mlaunch.launch.events.process")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "Event",
    "ExecutionComplete",
    "IncludeLaunchDescription",
    "ProcessExited",
    "ProcessIO",
    "ProcessStarted",
    "ProcessStderr",
    "ProcessStdin",
    "ProcessStdout",
    "ProcessTargetedEvent",
    "RunningProcessEvent",
    "Shutdown",
    "ShutdownProcess",
    "SignalProcess",
    "TimerEvent",
    "matches_action",
    "matches_executable",
    "matches_name",
    "matches_pid",
    "process",
]
