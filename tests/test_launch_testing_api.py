"""launch_testing's public API as ROS 2 Jazzy lays it out: every module path and name, the
loader, the runner's checks, the result classes and their JUnit report, ReadyAggregator,
StdoutReadyListener, process lookup before launch, and assertSequentialStdout's failure text."""

from __future__ import annotations

import importlib
import os
import types
import unittest
from collections.abc import Callable, Sequence
from typing import Any

import pytest

from mlaunch import compat
from mlaunch.launch.actions import ExecuteProcess, LaunchDescription, TimerAction
from mlaunch.launch.substitutions import EnvironmentVariable
from mlaunch.launch_testing.actions import ReadyToTest
from mlaunch.launch_testing.asserts import SequentialTextChecker
from mlaunch.launch_testing.decorator import post_shutdown_test
from mlaunch.launch_testing.junitxml import unittestResultsToXml
from mlaunch.launch_testing.loader import LoadTestsFromPythonModule
from mlaunch.launch_testing.parametrize import parametrize
from mlaunch.launch_testing.parse_arguments import parse_launch_arguments
from mlaunch.launch_testing.proc_info_handler import ProcInfoHandler
from mlaunch.launch_testing.ready_aggregator import ReadyAggregator
from mlaunch.launch_testing.test_result import FailResult, SkipResult
from mlaunch.launch_testing.test_result import TestResult as LaunchTestResult
from mlaunch.launch_testing.test_runner import LaunchTestRunner
from mlaunch.launch_testing.util import NoMatchingProcessException, resolveProcesses

# Every module of launch_testing and launch_pytest 3.4.3 and launch_testing_ros 0.26.6, with the
# public names each holds.
UPSTREAM_LAYOUT = {
    "launch_testing": [
        "ActiveIoHandler",
        "ActiveProcInfoHandler",
        "IoHandler",
        "ProcInfoHandler",
        "ReadyAggregator",
        "parametrize",
        "post_shutdown_test",
        "ready_to_test_action_timeout",
        "tools",
    ],
    "launch_testing.actions": ["ReadyToTest"],
    "launch_testing.actions.ready": ["ReadyToTest"],
    "launch_testing.asserts": [
        "EXIT_OK",
        "EXIT_SIGINT",
        "EXIT_SIGKILL",
        "EXIT_SIGQUIT",
        "EXIT_SIGSEGV",
        "NO_CMD_ARGS",
        "SequentialTextChecker",
        "assertDefaultStream",
        "assertExitCodes",
        "assertInStderr",
        "assertInStdout",
        "assertInStream",
        "assertSequentialStdout",
    ],
    "launch_testing.asserts.assert_exit_codes": ["EXIT_FORCED", "assertExitCodes"],
    "launch_testing.asserts.assert_output": ["assertInStream", "assertDefaultStream"],
    "launch_testing.asserts.assert_sequential_output": ["SequentialTextChecker"],
    "launch_testing.decorator": ["post_shutdown_test"],
    "launch_testing.event_handlers": ["StdoutReadyListener"],
    "launch_testing.event_handlers.stdout_ready_listener": ["StdoutReadyListener"],
    "launch_testing.io_handler": ["ActiveIoHandler", "IoHandler"],
    "launch_testing.junitxml": ["unittestCaseToXml", "unittestResultToXml", "unittestResultsToXml"],
    "launch_testing.launch_test": ["add_arguments", "main", "parse_arguments", "run"],
    "launch_testing.legacy": ["LaunchTestService", "output"],
    "launch_testing.legacy.output": [
        "create_output_lines_filter",
        "create_output_lines_test",
        "create_output_regex_test",
        "create_output_test_from_file",
        "get_rmw_output_filter",
    ],
    "launch_testing.loader": [
        "LoadTestsFromPythonModule",
        "PostShutdownTestLoader",
        "PreShutdownTestLoader",
        "TestRun",
    ],
    "launch_testing.markers": ["keep_alive", "retry_on_failure"],
    "launch_testing.parametrize": ["parametrize"],
    "launch_testing.parse_arguments": ["parse_launch_arguments"],
    "launch_testing.print_arguments": ["print_arguments_of_launch_description"],
    "launch_testing.proc_info_handler": ["ActiveProcInfoHandler", "ProcInfoHandler"],
    "launch_testing.pytest.hookspecs": ["pytest_launch_collect_makemodule"],
    "launch_testing.pytest.hooks": ["LaunchTestItem", "LaunchTestModule"],
    "launch_testing.ready_aggregator": ["ReadyAggregator"],
    "launch_testing.ready_to_test_action_timeout": ["ready_to_test_action_timeout"],
    "launch_testing.test_result": ["FailResult", "SkipResult", "TestResult"],
    "launch_testing.test_runner": ["LaunchTestRunner"],
    "launch_testing.tools": [
        "ProcessProxy",
        "basic_output_filter",
        "expect_output",
        "expected_output_from_file",
        "launch_process",
    ],
    "launch_testing.tools.output": [
        "get_default_filtered_patterns",
        "get_default_filtered_prefixes",
    ],
    "launch_testing.tools.process": ["ProcessProxy", "launch_process"],
    "launch_testing.tools.text": ["build_line_match", "build_text_match"],
    "launch_testing.util": [
        "KeepAliveProc",
        "NO_CMD_ARGS",
        "NoMatchingProcessException",
        "resolveProcesses",
    ],
    "launch_testing.util.proc_lookup": ["resolveProcesses"],
    "launch_testing_ros": [
        "DataRepublisher",
        "LaunchTestRunner",
        "MessagePump",
        "WaitForTopics",
        "tools",
    ],
    "launch_testing_ros.data_republisher": ["DataRepublisher"],
    "launch_testing_ros.message_pump": ["MessagePump"],
    "launch_testing_ros.pytest.hooks": ["LaunchROSTestItem", "LaunchROSTestModule"],
    "launch_testing_ros.test_runner": ["LaunchTestRunner"],
    "launch_testing_ros.tools": ["basic_output_filter"],
    "launch_testing_ros.tools.output": ["basic_output_filter", "get_rmw_output_filter"],
    "launch_testing_ros.wait_for_topics": ["WaitForTopics"],
    "launch_pytest": ["actions", "fixture", "tools"],
    "launch_pytest.actions": ["ReadyToTest"],
    "launch_pytest.fixture": ["fixture"],
    "launch_pytest.plugin": ["launch_context", "launch_service"],
    "launch_pytest.tools": ["process", "wait_for_output_sync", "assert_stderr"],
    "launch_pytest.tools.process": ["wait_for_start", "wait_for_exit_sync"],
}


@pytest.mark.parametrize("module", sorted(UPSTREAM_LAYOUT))
def test_every_upstream_module_path_serves_its_names(module: str) -> None:
    compat.install()
    served = importlib.import_module(module)
    missing = [name for name in UPSTREAM_LAYOUT[module] if not hasattr(served, name)]
    assert not missing, f"{module} lacks {missing}"
    # The same module object under mlaunch's own name (the prefix rule, no synonym).
    assert importlib.import_module(compat.target_of(module) or "") is served


def _module(
    generate: Callable[..., Any],
    *,
    active: Sequence[Callable[..., None]] = (),
    post: Sequence[Callable[..., None]] = (),
) -> Any:
    """A test module as launch_test would import it: a description and two test classes."""
    module: Any = types.ModuleType("test_module")
    module.generate_test_description = generate
    module.Active = _case_class("Active", active)
    module.Post = post_shutdown_test()(_case_class("Post", post))
    return module


def _case_class(name: str, tests: Sequence[Callable[..., None]]) -> type:
    namespace: dict[str, Any] = {test.__name__: test for test in tests}
    return type(name, (unittest.TestCase,), {**namespace, "__module__": "test_module"})


def test_loader_gives_one_run_per_parameter_with_active_and_post_tests_apart() -> None:
    def test_during(self: unittest.TestCase) -> None:
        return None

    def test_after(self: unittest.TestCase) -> None:
        return None

    @parametrize("value", [1, 2])
    def generate_test_description(value: int) -> LaunchDescription:
        return LaunchDescription([ReadyToTest()])

    runs = LoadTestsFromPythonModule(
        _module(generate_test_description, active=[test_during], post=[test_after]),
        name="pkg.file.launch_tests",
    )
    assert [str(run) for run in runs] == ["pkg.file.launch_tests[1]", "pkg.file.launch_tests[2]"]
    assert [case._testMethodName for case in runs[0].pre_shutdown_tests._tests[0]] == [  # type: ignore[attr-defined]
        "test_during[1]"
    ]
    assert [case._testMethodName for case in runs[1].post_shutdown_tests._tests[1]] == [  # type: ignore[attr-defined]
        "test_after[2]"
    ]


def test_ready_to_test_is_found_in_timers_and_its_absence_reported() -> None:
    ready = ReadyToTest()

    def nested() -> LaunchDescription:
        return LaunchDescription(
            [TimerAction(period=1.0, actions=[TimerAction(period=2.0, actions=[ready])])]
        )

    def without() -> LaunchDescription:
        return LaunchDescription([])

    _, context = LoadTestsFromPythonModule(_module(nested))[0].normalized_test_description(
        ready_fn=lambda: None
    )
    assert context == {} and len(ready._callbacks) == 1
    run = LoadTestsFromPythonModule(_module(without))[0]
    with pytest.raises(Exception, match="containing a ReadyToTest action"):
        run.normalized_test_description(ready_fn=lambda: None)


def test_runner_validate_names_the_argument_at_fault() -> None:
    def generate_test_description(ready_fn: object) -> None:
        return None

    @parametrize("wrong", [1])
    def parametrized() -> None:
        return None

    runner = LaunchTestRunner(LoadTestsFromPythonModule(_module(generate_test_description)))
    with pytest.raises(Exception, match="unexpected extra argument 'ready_fn'"):
        runner.validate()
    runner = LaunchTestRunner(LoadTestsFromPythonModule(_module(parametrized)))
    with pytest.raises(Exception, match="Could not find an argument .* 'wrong'"):
        runner.validate()
    runner = LaunchTestRunner([], launch_file_arguments=["name:="])
    with pytest.raises(RuntimeError, match="malformed launch argument 'name:='"):
        runner.validate()


def test_parse_launch_arguments_last_one_wins_and_values_may_hold_the_separator() -> None:
    assert parse_launch_arguments(["a:=1", "b:=x:=y", "a:=2"]) == [("a", "2"), ("b", "x:=y")]
    for bad in ("a", ":=1", "a:="):
        with pytest.raises(RuntimeError, match="expected format '<name>:=<value>'"):
            parse_launch_arguments([bad])


def test_whole_run_results_and_their_junit_report() -> None:
    def test_one(self: unittest.TestCase) -> None:
        return None

    def test_two(self: unittest.TestCase) -> None:
        return None

    run = LoadTestsFromPythonModule(_module(lambda: None, active=[test_one], post=[test_two]))[0]
    failed, skipped = FailResult(run, "it died"), SkipResult(run, skip_reason="not today")
    assert (failed.testsRun, failed.wasSuccessful(), len(failed.failures)) == (2, False, 2)
    assert (skipped.testsRun, skipped.wasSuccessful(), len(skipped.skipped)) == (2, True, 2)
    top = unittestResultsToXml(
        name="pkg.file", test_results={"dead": failed, "skip": skipped}
    ).getroot()
    assert top is not None
    assert (top.get("name"), top.get("tests"), top.get("failures")) == ("pkg.file", "4", "2")
    suites = {suite.get("name"): suite for suite in top}
    assert suites["skip"].get("skipped") == "2"
    case = suites["skip"].find("testcase[@name='test_one']")
    assert case is not None and case.get("classname") == "test_module.Active"
    skip = case.find("skipped")
    assert skip is not None and skip.get("message") == "not today"
    failure = suites["dead"].find("testcase/failure")
    assert failure is not None and "it died" in (failure.get("message") or "")


def test_test_result_times_every_test_it_ran() -> None:
    class Host(unittest.TestCase):
        def test_pass(self) -> None:
            return None

        def test_fail(self) -> None:
            self.fail("no")

    with open(os.devnull, "w") as devnull:
        result = unittest.TextTestRunner(stream=devnull, resultclass=LaunchTestResult).run(
            unittest.TestLoader().loadTestsFromTestCase(Host)
        )
    assert isinstance(result, LaunchTestResult)
    assert sorted(case._testMethodName for case in result.testCases) == ["test_fail", "test_pass"]
    assert all(seconds >= 0 for seconds in result.testTimes.values())
    element = unittestResultsToXml(test_results={"run": result}).getroot()
    assert element is not None
    assert (element.get("name"), element.get("tests"), element.get("failures")) == (
        "launch_test",
        "2",
        "1",
    )


def test_ready_aggregator_calls_once_after_the_nth_call() -> None:
    calls: list[int] = []
    aggregator = ReadyAggregator(lambda: calls.append(1), 3)
    aggregator.ready_fn()
    aggregator.ready_fn()
    assert calls == []
    aggregator.ready_fn()
    aggregator.ready_fn()
    assert calls == [1]


def test_a_process_not_yet_launched_is_named_by_its_plain_command_or_unknown() -> None:
    info = ProcInfoHandler()
    plain = ExecuteProcess(cmd=["python", "-c", ""])
    with pytest.raises(NoMatchingProcessException, match="No data recorded for proc python -c"):
        resolveProcesses(info, process=plain)
    resolved_later = ExecuteProcess(cmd=[EnvironmentVariable("HOME"), "-c", ""])
    with pytest.raises(NoMatchingProcessException, match="Unknown - Process not launched yet"):
        resolveProcesses(info, process=resolved_later)


# Five pieces of output, as ProcessIO events come: lines split unevenly across them.
PIECES = ["alpha\nbeta\n", "gamma\n", "delta\nepsilon\nzeta\n", "eta\n", "theta\niota\n"]


def test_sequential_failure_shows_three_lines_either_side_of_the_last_match() -> None:
    checker = SequentialTextChecker(PIECES)
    checker.assertInStdout("epsilon")
    with pytest.raises(AssertionError) as failure:
        checker.assertInStdout("alpha")
    # The last match ended inside piece 2; the window is pieces 0..4; three line breaks back
    # from the end of "epsilon" reach the start of "gamma", and the search forward starts one
    # past the line break right there, so it stops before "iota" (as the reference does).
    assert str(failure.value) == (
        "'alpha' not found in sequence after previous match.  "
        "The output near the last matched line:\ngamma\ndelta\nepsilon\nzeta\neta\ntheta"
    )
    fresh = SequentialTextChecker(PIECES)
    assert fresh.get_nearby_lines() == "alpha\nbeta\ngamma"
