"""``launch_testing.tools.process``: start a process from inside a running launch test.

``launch_process(launch_service, action, proc_info, proc_output)`` includes ``action`` into
the running launch and yields a ProcessProxy to wait on it; leaving the block stops it if it
still runs.
"""

from __future__ import annotations

from mlaunch.launch.actions.execute_process import ExecuteProcess
from mlaunch.launch.events.include_launch_description import IncludeLaunchDescription
from mlaunch.launch.events.matchers import matches_action
from mlaunch.launch.events.process.process_exited import ProcessExited
from mlaunch.launch.events.process.process_started import ProcessStarted
from mlaunch.launch.events.process.shutdown_process import ShutdownProcess
from mlaunch.launch.launch_description import LaunchDescription

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


class _Waited:
    """A bool that also shows the output it was decided on (for assertion messages)."""

    def __init__(self, result: bool, output: Any) -> None:
        self._result = result
        self._output = output

    def __bool__(self) -> bool:
        return self._result

    def __repr__(self) -> str:
        return f"<BoolWithText({self._result}): {self._output!r}>"


class ProcessProxy:
    """A process of the running launch seen through proc_info and proc_output."""

    def __init__(
        self,
        process_action: Any,
        proc_info: Any,
        proc_output: Any,
        *,
        output_filter: Callable[[str], str] | None = None,
    ) -> None:
        if output_filter is not None and not callable(output_filter):
            raise TypeError(f"Expected 'output_filter' to be callable but got {output_filter!r}")
        self._process_action = process_action
        self._proc_info = proc_info
        self._proc_output = proc_output
        self._output_filter = output_filter

    @property
    def target_process_action(self) -> Any:
        return self._process_action

    def _text(self, fd: int | None) -> str:
        try:
            events = self._proc_output[self._process_action]
        except (KeyError, TypeError):
            events = []  # not started, or nothing printed yet
        text = "".join(
            e.text.decode("utf-8", "replace") for e in events if fd is None or e.fd == fd
        )
        return self._output_filter(text) if self._output_filter is not None else text

    @property
    def stdout(self) -> str:
        return self._text(1)

    @property
    def stderr(self) -> str:
        return self._text(2)

    @property
    def output(self) -> str:
        return self._text(None)

    def _event(self) -> Any:
        if self._process_action not in self._proc_info.processes():
            return None
        return self._proc_info[self._process_action]

    @property
    def running(self) -> bool:
        return isinstance(self._event(), ProcessStarted)

    @property
    def terminated(self) -> bool:
        return isinstance(self._event(), ProcessExited)

    @property
    def exit_code(self) -> int:
        return int(self._proc_info[self._process_action].returncode)

    def wait_for_shutdown(self, timeout: float | None = None) -> bool:
        with self._proc_info.proc_event:
            return bool(self._proc_info.proc_event.wait_for(lambda: self.terminated, timeout))

    def wait_for_output(
        self, condition: Callable[[str], bool] | None = None, timeout: float | None = None
    ) -> _Waited:
        """Wait until the output so far satisfies ``condition`` (any output when None)."""
        if condition is None:

            def condition(output: str) -> bool:
                return True

        if not callable(condition):
            raise TypeError(f"Expected 'condition' to be callable but got {condition!r}")
        seen = [""]

        def satisfied() -> bool:
            seen[0] = self.output
            return self.running and condition(seen[0])

        with self._proc_output.io_event:
            result = self._proc_output.io_event.wait_for(satisfied, timeout)
        return _Waited(bool(result), seen[0])


class _LaunchedProcess:
    """The context manager launch_process returns."""

    def __init__(self, launch_service: Any, proxy: ProcessProxy) -> None:
        self.launch_service = launch_service
        self.proxy = proxy

    def __enter__(self) -> ProcessProxy:
        action = self.proxy.target_process_action
        self.launch_service.emit_event(IncludeLaunchDescription(LaunchDescription([action])))
        return self.proxy

    def __exit__(self, *exc_info: object) -> None:
        if not self.proxy.terminated:
            action = self.proxy.target_process_action
            self.launch_service.emit_event(ShutdownProcess(process_matcher=matches_action(action)))


def launch_process(
    launch_service: Any, process_action: Any, proc_info: Any, proc_output: Any, **kwargs: Any
) -> _LaunchedProcess:
    """Start ``process_action`` in the running launch; ``with`` it to get a ProcessProxy."""
    if not isinstance(process_action, ExecuteProcess):
        raise TypeError(
            f"process_action must be an ExecuteProcess, not {type(process_action).__name__}"
        )
    return _LaunchedProcess(
        launch_service, ProcessProxy(process_action, proc_info, proc_output, **kwargs)
    )


__all__ = ["ProcessProxy", "launch_process"]
