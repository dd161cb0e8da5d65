"""Run TestRuns: launch on the main thread, active tests beside it, post-shutdown tests after.

For each run: the description is launched by a LaunchService (mlaunch's supervisor) on the
main thread, which owns the signals; the active tests start on a worker thread once
ReadyToTest fires and shut the launch down when they finish; the post-shutdown tests then run
on the main thread against what was recorded.
"""

from __future__ import annotations

import threading
import unittest

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
from mlaunch.launch.event_handlers.on_process_exit import OnProcessExit
from mlaunch.launch.event_handlers.on_process_io import OnProcessIO
from mlaunch.launch.event_handlers.on_process_start import OnProcessStart
from mlaunch.launch.launch_description import LaunchDescription
from mlaunch.launch_testing.io_handler import ActiveIoHandler
from mlaunch.launch_testing.parse_arguments import parse_launch_arguments
from mlaunch.launch_testing.proc_info_handler import ActiveProcInfoHandler
from mlaunch.launch_testing.test_result import FailResult, SkipResult, TestResult

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from mlaunch.launch_testing.loader import TestRun


class _LaunchDied(Exception):
    """The launch ended before the active tests did (every process exited, or Ctrl-C)."""


class _RunnerWorker:
    """One TestRun: its launch, its active tests thread, its post-shutdown tests."""

    def __init__(
        self,
        test_run: TestRun,
        launch_arguments: Sequence[str],
        debug: bool,
        screen: Callable[[bytes], object] | None,
    ) -> None:
        self.test_run = test_run
        self.launch_arguments = list(launch_arguments)
        self.service = LaunchService(argv=self.launch_arguments, debug=debug, screen=screen)
        self.ready = threading.Event()
        self.done = threading.Event()
        self.results: TestResult | None = None

    def run(self) -> TestResult:
        run = self.test_run
        description, context = run.normalized_test_description(ready_fn=self.ready.set)
        proc_info = ActiveProcInfoHandler()
        proc_output = ActiveIoHandler()
        test_args = dict(parse_launch_arguments(self.launch_arguments))
        active = {
            "launch_service": self.service,
            "proc_info": proc_info,
            "proc_output": proc_output,
            "test_args": test_args,
        }
        run.bind(run.pre_shutdown_tests, active, {**context, **run.param_args, **active})
        post = {
            "proc_info": proc_info._proc_info_handler,
            "proc_output": proc_output._io_handler,
            "test_args": test_args,
        }
        run.bind(run.post_shutdown_tests, post, {**context, **run.param_args, **post})
        self.service.include_launch_description(
            LaunchDescription(
                [
                    RegisterEventHandler(OnProcessStart(on_start=_call(proc_info.append))),
                    RegisterEventHandler(
                        OnProcessStart(on_start=_call(lambda e: proc_output.track(e.process_name)))
                    ),
                    RegisterEventHandler(OnProcessExit(on_exit=_call(proc_info.append))),
                    RegisterEventHandler(
                        OnProcessIO(on_stdout=proc_output.append, on_stderr=proc_output.append)
                    ),
                    description,
                ]
            )
        )
        tests = threading.Thread(target=self._run_test, name="active tests", daemon=True)
        tests.start()
        self.service.run(shutdown_when_idle=not run.markers.get("keep_alive", False))
        if not self.done.is_set():
            print("Processes under test stopped before tests completed")
            _print_failed_processes(proc_info, proc_output)
            raise _LaunchDied()
        after = unittest.TextTestRunner(verbosity=2, resultclass=TestResult).run(
            run.post_shutdown_tests
        )
        assert self.results is not None and isinstance(after, TestResult)
        self.results.append(after)
        return self.results

    def _run_test(self) -> None:
        if not self.ready.wait(self.test_run.timeout):
            print("Timed out waiting for processes to start up")
            self.service.shutdown()
            return
        try:
            result = unittest.TextTestRunner(verbosity=2, resultclass=TestResult).run(
                self.test_run.pre_shutdown_tests
            )
            assert isinstance(result, TestResult)
            self.results = result
        finally:
            self.done.set()
            self.service.shutdown()


def _call(function: Callable[[Any], object]) -> Callable[[Any, Any], None]:
    """An event handler callable(event, context) that only records the event."""

    def handler(event: Any, context: Any) -> None:
        function(event)

    return handler


def _print_failed_processes(proc_info: ActiveProcInfoHandler, proc_output: ActiveIoHandler) -> None:
    for info in proc_info:
        if getattr(info, "returncode", 0) == 0:
            continue
        print(f"Process '{info.process_name}' exited with {info.returncode}")
        print(f"##### '{info.process_name}' output #####")
        try:
            for io in proc_output[info.action]:
                print(io.text.decode("utf-8", "replace"), end="")
        except KeyError:
            pass  # it printed nothing
        print("#" * (len(info.process_name) + 21))


class LaunchTestRunner:
    """Runs every TestRun of a file in turn; ``run()`` -> {TestRun: result}."""

    def __init__(
        self,
        test_runs: list[TestRun],
        launch_file_arguments: Sequence[str] = (),
        debug: bool = False,
        screen: Callable[[bytes], object] | None = None,
    ) -> None:
        self.test_runs = test_runs
        self.launch_file_arguments = list(launch_file_arguments)
        self.debug = debug
        self.screen = screen

    def validate(self) -> None:
        """The launch arguments are well formed, and each parametrized value has a parameter of
        generate_test_description and each of its parameters a value (as launch_testing says)."""
        import inspect

        parse_launch_arguments(self.launch_file_arguments)
        for run in self.test_runs:
            spec = inspect.getfullargspec(inspect.unwrap(run.description_function))
            names = spec.args + spec.kwonlyargs
            for name in run.param_args:
                if name not in names:
                    raise Exception(
                        "Could not find an argument in generate_test_description matching"
                        f" prametrized argument '{name}'"
                    )
            for name in names:
                if name not in run.param_args:
                    raise Exception(
                        f"generate_test_description has unexpected extra argument '{name}'"
                    )

    def run(self) -> dict[TestRun, unittest.TestResult]:
        results: dict[TestRun, unittest.TestResult] = {}
        for run in self.test_runs:
            if len(self.test_runs) > 1:
                print(f"\nStarting test run {run}")
            try:
                worker = _RunnerWorker(run, self.launch_file_arguments, self.debug, self.screen)
                results[run] = worker.run()
            except unittest.SkipTest as skip:
                print(f"{run} is skipped: {skip}")
                results[run] = SkipResult(run, skip_reason=str(skip))
            except _LaunchDied:
                results[run] = FailResult(run, "Launch stopped before the active tests finished.")
                break  # most likely Ctrl-C: the other runs would not fare better
        return results
