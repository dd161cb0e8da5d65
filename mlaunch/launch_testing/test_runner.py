"""Run TestRuns: launch on the main thread, active tests beside it, post-shutdown tests after.

For each run: the description is launched by a LaunchService (mlaunch's supervisor) on the
main thread, which owns the signals; the active tests start on a worker thread once
ReadyToTest fires and shut the launch down when they finish; the post-shutdown tests then run
on the main thread against what was recorded.
"""

from __future__ import annotations

import threading
import time
import unittest

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import LaunchDescription, RegisterEventHandler
from mlaunch.launch.event_handlers import OnProcessExit, OnProcessIO, OnProcessStart
from mlaunch.launch_testing.io_handler import ActiveIoHandler
from mlaunch.launch_testing.proc_info_handler import ActiveProcInfoHandler

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from mlaunch.launch_testing.loader import TestRun


class TestResult(unittest.TextTestResult):
    """A TextTestResult that remembers every test it ran and how long each took."""

    def __init__(self, stream: Any = None, descriptions: Any = None, verbosity: Any = None):
        super().__init__(stream, descriptions, verbosity)
        self._times: dict[unittest.TestCase, list[float]] = {}

    @property
    def testCases(self) -> list[unittest.TestCase]:
        return list(self._times)

    @property
    def testTimes(self) -> dict[unittest.TestCase, float]:
        return {case: end - start for case, (start, end) in self._times.items()}

    def startTest(self, test: unittest.TestCase) -> None:
        self._times[test] = [time.monotonic(), time.monotonic()]
        super().startTest(test)

    def stopTest(self, test: unittest.TestCase) -> None:
        self._times[test][1] = time.monotonic()
        super().stopTest(test)

    def append(self, other: TestResult) -> None:
        """Add the results of the post-shutdown tests to the active tests' results."""
        self._times.update(other._times)
        self.failures += other.failures
        self.errors += other.errors
        self.testsRun += other.testsRun
        self.skipped += other.skipped
        self.expectedFailures += other.expectedFailures
        self.unexpectedSuccesses += other.unexpectedSuccesses


class _WholeRunResult(unittest.TestResult):
    """Every test of a run failed (the launch died early) or skipped (a skipped description)."""

    def __init__(self, test_run: TestRun, *, failure: str | None = None, skip: str = "") -> None:
        super().__init__()
        self.failed = failure is not None
        for case in test_run.all_cases():
            if failure is not None:
                self.addFailure(case, (Exception, Exception(failure), None))  # type: ignore[arg-type]
            else:
                self.addSkip(case, skip)
            self.testsRun += 1

    @property
    def testCases(self) -> list[Any]:
        return [case for case, _ in (self.failures if self.failed else self.skipped)]

    @property
    def testTimes(self) -> dict[Any, float]:
        return dict.fromkeys(self.testCases, 0.0)

    def wasSuccessful(self) -> bool:
        return not self.failed


class _LaunchDied(Exception):
    """The launch ended before the active tests did (every process exited, or Ctrl-C)."""


def parse_launch_arguments(arguments: Sequence[str]) -> list[tuple[str, str]]:
    """``name:=value`` items -> (name, value) pairs; anything else is a usage error."""
    pairs = []
    for item in arguments:
        name, sep, value = item.partition(":=")
        if not sep or not name:
            raise ValueError(
                f"malformed launch argument {item!r}, expected format '<name>:=<value>'"
            )
        pairs.append((name, value))
    return pairs


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
        description, context = run.test_description(self.ready.set)
        proc_info = ActiveProcInfoHandler()
        proc_output = ActiveIoHandler()
        test_args = dict(parse_launch_arguments(self.launch_arguments))
        values = {**context, **run.param_args, "test_args": test_args}
        run.bind(
            run.pre_shutdown_tests,
            {
                **values,
                "launch_service": self.service,
                "proc_info": proc_info,
                "proc_output": proc_output,
            },
        )
        run.bind(
            run.post_shutdown_tests,
            {
                **values,
                "proc_info": proc_info._proc_info_handler,
                "proc_output": proc_output._io_handler,
            },
        )
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
        tests = threading.Thread(target=self._run_active_tests, name="active tests", daemon=True)
        tests.start()
        self.service.run(shutdown_when_idle=not run.markers.get("keep_alive", False))
        if not self.done.is_set():
            print("Processes under test stopped before tests completed")
            _print_failed_processes(proc_info, proc_output)
            raise _LaunchDied()
        post = unittest.TextTestRunner(verbosity=2, resultclass=TestResult).run(
            run.post_shutdown_tests
        )
        assert self.results is not None and isinstance(post, TestResult)
        self.results.append(post)
        return self.results

    def _run_active_tests(self) -> None:
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
        """Parametrized names must be parameters of generate_test_description, and back."""
        import inspect

        parse_launch_arguments(self.launch_file_arguments)
        for run in self.test_runs:
            base = inspect.unwrap(run.description_function)
            spec = inspect.getfullargspec(base)
            names = [n for n in spec.args + spec.kwonlyargs if n != "ready_fn"]
            for name in run.param_args:
                if name not in names:
                    raise Exception(
                        f"generate_test_description has no argument {name!r} for the"
                        " parametrized value"
                    )
            for name in names:
                if name not in run.param_args:
                    raise Exception(
                        f"generate_test_description has unexpected extra argument {name!r}"
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
                results[run] = _WholeRunResult(run, skip=str(skip))
            except _LaunchDied:
                results[run] = _WholeRunResult(
                    run, failure="Launch stopped before the active tests finished."
                )
                break  # most likely Ctrl-C: the other runs would not fare better
        return results
