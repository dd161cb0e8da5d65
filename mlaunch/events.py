"""Events, with the names of ROS 2 launch, and the matchers handlers use to pick processes."""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


class Event:
    """Base of everything the supervisor announces or a launch file emits."""

    name = "launch.events.Event"


@dataclass
class Shutdown(Event):
    reason: str = "reason not given"
    due_to_sigint: bool = False


@dataclass
class ProcessEvent(Event):
    """Fields of ROS 2's process events: the action, the label, argv, cwd, env and pid."""

    action: Any = None
    name: str = ""
    cmd: list[str] = field(default_factory=list)
    cwd: str | None = None
    env: dict[str, str] | None = None
    pid: int = 0


@dataclass
class ProcessStarted(ProcessEvent):
    pass


@dataclass
class ProcessExited(ProcessEvent):
    returncode: int = 0


@dataclass
class ProcessIO(ProcessEvent):
    text: bytes = b""
    fd: int = 1


class ProcessStdout(ProcessIO):
    pass


class ProcessStderr(ProcessIO):
    pass


ProcessMatcher = Callable[[Any], bool]


@dataclass
class ShutdownProcess(Event):
    """Run the stop ladder on the processes the matcher selects."""

    process_matcher: ProcessMatcher | None = None


@dataclass
class SignalProcess(Event):
    signal_number: int = 2
    process_matcher: ProcessMatcher | None = None


def matches_action(target_action: Any) -> ProcessMatcher:
    return lambda process: getattr(process, "action", None) is target_action


def matches_pid(target_pid: int) -> ProcessMatcher:
    return lambda process: getattr(process, "pid", None) == target_pid


def matches_name(target_name: str) -> ProcessMatcher:
    return lambda process: getattr(process, "label", None) == target_name


def matches_executable(executable_name: str) -> ProcessMatcher:
    def match(process: Any) -> bool:
        argv: tuple[str, ...] = tuple(getattr(process, "argv", ()))
        return bool(argv) and argv[0].endswith(executable_name)

    return match


# ROS 2 keeps process events in launch.events.process; both spellings resolve here.
process = sys.modules[__name__]

__all__ = [
    "Event",
    "ProcessExited",
    "ProcessIO",
    "ProcessStarted",
    "ProcessStderr",
    "ProcessStdout",
    "Shutdown",
    "ShutdownProcess",
    "SignalProcess",
    "matches_action",
    "matches_executable",
    "matches_name",
    "matches_pid",
]
