"""proc_info: the last start or exit event of every process, and waiting for them.

``ProcInfoHandler`` is what post-shutdown tests get (nothing changes any more);
``ActiveProcInfoHandler`` is what active tests get: the runner's event handlers append to it
from the launch loop while the tests wait on its condition from their thread.
"""

from __future__ import annotations

import threading

from mlaunch.launch.events.process.process_exited import ProcessExited
from mlaunch.launch_testing.util.proc_lookup import NoMatchingProcessException, resolveProcesses

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from typing import Any


class ProcInfoHandler:
    """Process action -> its latest ProcessStarted or ProcessExited event."""

    def __init__(self) -> None:
        self._info: dict[Any, Any] = {}

    def append(self, process_info: Any) -> None:
        self._info[process_info.action] = process_info

    def __iter__(self) -> Iterator[Any]:
        return iter(list(self._info.values()))

    def processes(self) -> list[Any]:
        return list(self._info)

    def process_names(self) -> list[str]:
        return [action.process_details["name"] for action in self._info]

    def __getitem__(self, key: Any) -> Any:
        if not isinstance(key, str):
            return self._info[key]
        for action, info in self._info.items():
            if key in action.process_details["name"]:
                return info
        raise KeyError(key)


class ActiveProcInfoHandler:
    """ProcInfoHandler behind a condition, for tests that wait on processes while they run."""

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._proc_info_handler = ProcInfoHandler()

    @property
    def proc_event(self) -> threading.Condition:
        return self._condition

    def append(self, process_info: Any) -> None:
        with self._condition:
            self._proc_info_handler.append(process_info)
            self._condition.notify_all()

    def __iter__(self) -> Iterator[Any]:
        with self._condition:
            return iter(list(self._proc_info_handler))

    def processes(self) -> list[Any]:
        with self._condition:
            return self._proc_info_handler.processes()

    def process_names(self) -> list[str]:
        with self._condition:
            return self._proc_info_handler.process_names()

    def __getitem__(self, key: Any) -> Any:
        with self._condition:
            return self._proc_info_handler[key]

    def _wait(self, found: Callable[[], bool], timeout: float) -> bool:
        with self._condition:
            return self._condition.wait_for(found, timeout=timeout)

    def _event_of(self, process: Any, cmd_args: Any) -> Any:
        action = resolveProcesses(
            self._proc_info_handler, process=process, cmd_args=cmd_args, strict_proc_matching=True
        )[0]
        return self._proc_info_handler[action]

    def assertWaitForShutdown(
        self, process: Any, cmd_args: Any = None, *, timeout: float = 10
    ) -> None:
        """Wait until ``process`` has exited; fail after ``timeout`` seconds."""

        def exited() -> bool:
            try:
                return isinstance(self._event_of(process, cmd_args), ProcessExited)
            except NoMatchingProcessException:
                return False

        assert self._wait(exited, timeout), f"Timed out waiting for process '{process}' to finish"

    def assertWaitForStartup(
        self, process: Any, cmd_args: Any = None, *, timeout: float = 10
    ) -> None:
        """Wait until ``process`` has started; fail after ``timeout`` seconds."""

        def started() -> bool:
            try:
                self._event_of(process, cmd_args)
            except NoMatchingProcessException:
                return False
            return True

        assert self._wait(started, timeout), f"Timed out waiting for process '{process}' to start"
