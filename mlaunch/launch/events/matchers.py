"""``launch.events.matchers``: the matcher of a process by its action; how the engine's matchers
say they see the running process.
"""

from __future__ import annotations

from collections.abc import Callable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    ProcessMatcher = Callable[[Any], bool]
else:  # the same at run time, without typing.Any
    ProcessMatcher = Callable[[object], bool]


# A process matcher written in a launch file is given a running process's action, as launch's
# (``lambda action: action is talker``). The matchers below are given the running process
# itself (its action, pid, label and argv: an action may run more than one process here).
SEES_PROCESS = "sees_process"


def _sees_process(match: ProcessMatcher) -> ProcessMatcher:
    setattr(match, SEES_PROCESS, True)
    return match


class _ProcessOfAction:
    """The matcher of a running process by its action (a class, not a lambda: a plan that holds
    it can be stored in the plan cache)."""

    __slots__ = ("target_action",)

    def __init__(self, target_action: Any) -> None:
        self.target_action = target_action

    def __call__(self, process: object) -> bool:
        return getattr(process, "action", None) is self.target_action


setattr(_ProcessOfAction, SEES_PROCESS, True)


def matches_action(target_action: Any) -> ProcessMatcher:
    return _ProcessOfAction(target_action)
