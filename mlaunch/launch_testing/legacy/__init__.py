"""``launch_testing.legacy``: LaunchTestService, launch_testing's first API (before
generate_test_description): fixture and test actions added to a description, output tests on
processes, and a return code that says whether the tests passed.

It is built on launch's own event handlers, as in ROS 2: a test's outcome shuts the launch down
once no test is still armed.
"""

from __future__ import annotations

from mlaunch.launch.actions.emit_event import EmitEvent
from mlaunch.launch.actions.execute_process import ExecuteProcess
from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
from mlaunch.launch.event_handlers.on_execution_complete import OnExecutionComplete
from mlaunch.launch.event_handlers.on_process_exit import OnProcessExit
from mlaunch.launch.event_handlers.on_process_io import OnProcessIO
from mlaunch.launch.event_handlers.on_shutdown import OnShutdown
from mlaunch.launch.events.shutdown import Shutdown
from mlaunch.launch_testing.legacy import output

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

ARMED, FINISHED, DROPPED, FAILED, SUCCEEDED = "armed", "finished", "dropped", "failed", "succeeded"


def _shutdown(reason: str) -> list[Any]:
    return [EmitEvent(event=Shutdown(reason=reason))]


class LaunchTestService:
    """Tracks the tests added to launch descriptions; ``run(launch_service)`` runs them."""

    def __init__(self) -> None:
        self.__tests: dict[str, str] = {}  # test name -> state, in the order added
        self.__processes_rc: dict[str, int] = {}  # process name -> the code it failed with

    # --- test states -------------------------------------------------------------------------

    def _arm(self, test_name: str) -> None:
        assert test_name not in self.__tests
        self.__tests[test_name] = ARMED

    def _all_done(self) -> bool:
        return all(state != ARMED for state in self.__tests.values())

    def _finish(self, test_name: str) -> list[Any] | None:
        """Done without a verdict; the launch ends once every test is done."""
        self.__tests[test_name] = FINISHED
        return _shutdown("all tests finished") if self._all_done() else None

    def _drop(self, test_name: str) -> None:
        self.__tests[test_name] = DROPPED

    def _fail(self, test_name: str, reason: str) -> list[Any]:
        """Failed: the tests still armed are dropped and the launch shuts down."""
        self.__tests[test_name] = FAILED
        for name, state in self.__tests.items():
            if state == ARMED:
                self.__tests[name] = DROPPED
        return _shutdown(reason)

    def _succeed(self, test_name: str, side_effect: str | None = None) -> list[Any]:
        self.__tests[test_name] = SUCCEEDED
        if self._all_done():
            return _shutdown("all tests finished")
        if side_effect == "shutdown":
            return _shutdown("shutdown after test")
        return []

    # --- what a description gets -------------------------------------------------------------

    def add_fixture_action(
        self, launch_description: Any, action: Any, exit_allowed: Any = (0,)
    ) -> Any:
        """Add ``action`` as a fixture: a process of it exiting with a code not in
        ``exit_allowed`` (a list of codes, or a bool for any) shuts the launch down and fails
        the run with that code."""
        launch_description.add_action(action)
        if isinstance(action, ExecuteProcess):
            launch_description.add_action(
                RegisterEventHandler(
                    OnProcessExit(target_action=action, on_exit=self._fixture_exit(exit_allowed))
                )
            )
        return action

    def _fixture_exit(self, exit_allowed: Any) -> Callable[[Any, Any], Any]:
        def on_exit(event: Any, context: Any) -> Any:
            allowed = exit_allowed
            if isinstance(exit_allowed, (list, tuple)):
                allowed = event.returncode in exit_allowed
            if context.is_shutdown or allowed:
                return None
            name = event.action.process_details["name"]
            self.__processes_rc[name] = event.returncode or 1
            return _shutdown(f"{name} fixture process died!")

        return on_exit

    def add_test_action(self, launch_description: Any, action: Any) -> Any:
        """Add ``action`` as a test: a process passes when it exits 0, another action when it
        completes without an exception. Every test done ends the launch."""
        test_name = f"test_{id(action)}"
        if isinstance(action, ExecuteProcess):
            handler: Any = OnProcessExit(target_action=action, on_exit=self._test_exit(test_name))
        else:
            handler = OnExecutionComplete(
                target_action=action, on_completion=self._test_completion(test_name)
            )
        launch_description.add_action(RegisterEventHandler(handler))
        launch_description.add_action(action)
        self._arm(test_name)
        return action

    def _test_exit(self, test_name: str) -> Callable[[Any, Any], Any]:
        def on_exit(event: Any, context: Any) -> Any:
            if event.returncode == 0:
                return self._succeed(test_name)
            name = event.action.process_details["name"]
            self.__processes_rc[name] = event.returncode
            return self._fail(test_name, reason=f"{name} test failed!")

        return on_exit

    def _test_completion(self, test_name: str) -> Callable[[Any, Any], Any]:
        def on_completion(event: Any, context: Any) -> Any:
            future = event.action.get_asyncio_future()
            if future is not None:
                if future.cancelled():
                    return self._drop(test_name)
                if future.exception() is not None:
                    return self._fail(test_name, str(future.exception()))
            return self._succeed(test_name)

        return on_completion

    def add_output_test(
        self,
        launch_description: Any,
        action: Any,
        output_test: tuple[Any, Any, Any, Any],
        test_suffix: str = "output",
        output_filter: Callable[[bytes], bytes] | None = None,
        side_effect: str | None = None,
    ) -> Any:
        """Test the stdout of the process ``action`` with ``output_test`` (one of
        ``output.create_*``): it passes once every expectation matched, fails at shutdown
        otherwise. ``side_effect='shutdown'`` ends the launch when it passes."""
        assert isinstance(action, ExecuteProcess)
        test_name = f"test_{id(action)}_{test_suffix}"
        check = _OutputCheck(self, test_name, output_test, output_filter, side_effect)
        for handler in (
            OnProcessExit(target_action=action, on_exit=check.on_exit),
            OnShutdown(on_shutdown=check.on_shutdown_of(action)),
            OnProcessIO(target_action=action, on_stdout=check.on_stdout),
        ):
            launch_description.add_action(RegisterEventHandler(handler))
        self._arm(test_name)
        return action

    def run(self, launch_service: Any, *args: Any, **kwargs: Any) -> int:
        """Run the launch: its return code, else the first code a test or fixture process
        failed with, else 1 when a test failed, else 0."""
        rc = int(launch_service.run(*args, **kwargs))
        if rc != 0:
            return rc
        failed = [code for code in self.__processes_rc.values() if code != 0]
        if failed:
            return failed[0]
        return 1 if FAILED in self.__tests.values() else 0


class _OutputCheck:
    """One output test: the output so far and the expectations not matched yet."""

    def __init__(
        self,
        service: LaunchTestService,
        test_name: str,
        output_test: tuple[Any, Any, Any, Any],
        output_filter: Callable[[bytes], bytes] | None,
        side_effect: str | None,
    ) -> None:
        self.service = service
        self.test_name = test_name
        self.out, self.collate, self.match, patterns = output_test
        self.pending = list(patterns)
        assert any(self.pending)
        self.output_filter = output_filter or (lambda text: text)
        self.side_effect = side_effect

    def on_exit(self, event: Any, context: Any) -> Any:
        # Finished, not failed, while output is still expected: the exit and the last output
        # events may come in either order; the shutdown gives the verdict.
        if any(self.pending):
            return self.service._finish(self.test_name)
        return None

    def on_shutdown_of(self, action: Any) -> Callable[[Any, Any], None]:
        def on_shutdown(event: Any, context: Any) -> None:
            # As launch_testing: unmatched output is marked failed, then the test succeeded
            # all the same. The exit and the last output events race, so at shutdown an output
            # test gives no failing verdict (a process's exit code still does).
            if any(self.pending):
                name = action.process_details["name"]
                self.service._fail(self.test_name, f"not all {name} output matched!")
            self.service._succeed(self.test_name, self.side_effect)

        return on_shutdown

    def on_stdout(self, event: Any) -> Any:
        self.out = self.collate(self.out, self.output_filter(event.text))
        self.pending = [pattern for pattern in self.pending if not self.match(self.out, pattern)]
        if any(self.pending):
            return None
        return self.service._succeed(self.test_name, self.side_effect)


__all__ = ["LaunchTestService", "output"]
