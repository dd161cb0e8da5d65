"""proc_output: what every process printed, in order, and waiting for a text to appear.

``IoHandler`` is what post-shutdown tests get; ``ActiveIoHandler`` is what active tests get:
the runner's OnProcessIO handler appends to it from the launch loop while tests wait on its
condition from their thread.
"""

from __future__ import annotations

import threading

from mlaunch.launch_testing.asserts.assert_output import assertInStream
from mlaunch.launch_testing.util.proc_lookup import NoMatchingProcessException, resolveProcesses

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterator
    from typing import Any


class IoHandler:
    """Every ProcessIO event in arrival order, and per process name."""

    def __init__(self) -> None:
        self._sequence: list[Any] = []
        self._by_name: dict[str, list[Any]] = {}

    def track(self, process_name: str) -> None:
        self._by_name.setdefault(process_name, [])

    def append(self, process_io: Any) -> None:
        self._sequence.append(process_io)
        self._by_name.setdefault(process_io.process_name, []).append(process_io)

    def __iter__(self) -> Iterator[Any]:
        return iter(list(self._sequence))

    def processes(self) -> list[Any]:
        """The actions of the processes that printed something."""
        return [events[0].action for events in self._by_name.values() if events]

    def process_names(self) -> list[str]:
        return list(self._by_name)

    def __getitem__(self, key: Any) -> list[Any]:
        """The output events of a process, by name or by its action."""
        if isinstance(key, str):
            return list(self._by_name[key])
        return list(self._by_name[key.process_details["name"]])


class ActiveIoHandler:
    """IoHandler behind a condition, for tests that wait on output while processes run."""

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._io_handler = IoHandler()

    @property
    def io_event(self) -> threading.Condition:
        return self._condition

    def track(self, process_name: str) -> None:
        with self._condition:
            self._io_handler.track(process_name)
            self._condition.notify_all()

    def append(self, process_io: Any) -> None:
        with self._condition:
            self._io_handler.append(process_io)
            self._condition.notify_all()

    def __iter__(self) -> Iterator[Any]:
        with self._condition:
            return iter(list(self._io_handler))

    def processes(self) -> list[Any]:
        with self._condition:
            return self._io_handler.processes()

    def process_names(self) -> list[str]:
        with self._condition:
            return self._io_handler.process_names()

    def __getitem__(self, key: Any) -> list[Any]:
        with self._condition:
            return self._io_handler[key]

    def assertWaitFor(self, *args: Any, **kwargs: Any) -> None:
        assert self.waitFor(*args, **kwargs), "Waiting for output timed out"

    def waitFor(
        self,
        expected_output: Any,
        process: Any = None,
        cmd_args: Any = None,
        *,
        strict_proc_matching: bool = True,
        output_filter: Any = None,
        timeout: float = 10,
        strip_ansi_escape_sequences: bool = True,
        stream: str = "stderr",
    ) -> bool:
        """Wait up to ``timeout`` seconds for ``expected_output`` in ``stream`` (stderr unless
        told, as ROS 2) of ``process`` (any process when None). True when it appeared."""

        def found() -> bool:
            try:
                assertInStream(
                    self._io_handler,
                    expected_output,
                    process,
                    cmd_args,
                    output_filter=output_filter,
                    strict_proc_matching=strict_proc_matching,
                    strip_ansi_escape_sequences=strip_ansi_escape_sequences,
                    stream=stream,
                )
            except (NoMatchingProcessException, AssertionError):
                return False  # nothing printed yet, or not this text yet
            return True

        with self._condition:
            success = self._condition.wait_for(found, timeout=timeout)
        if not success:
            # A process that never matched at all is most likely a wrong name: say so.
            try:
                resolveProcesses(
                    self, process=process, cmd_args=cmd_args, strict_proc_matching=False
                )
            except NoMatchingProcessException:
                raise Exception(
                    f"After timeout, found no processes matching '{process}'  It either doesn't"
                    " exist, was never launched, or didn't generate any output"
                ) from None
        return success
