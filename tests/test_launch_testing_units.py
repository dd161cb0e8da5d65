"""Pure parts of launch_testing: text matching, ordered output checks, finding processes by
name, parametrize and retry_on_failure (no process is started here)."""

from __future__ import annotations

import re
import unittest

import pytest

from mlaunch.launch.actions import ExecuteProcess
from mlaunch.launch.events import ProcessExited, ProcessIO
from mlaunch.launch_testing.asserts import SequentialTextChecker, assertExitCodes, assertInStdout
from mlaunch.launch_testing.io_handler import IoHandler
from mlaunch.launch_testing.markers import retry_on_failure
from mlaunch.launch_testing.parametrize import parametrize
from mlaunch.launch_testing.proc_info_handler import ProcInfoHandler
from mlaunch.launch_testing.tools import basic_output_filter, expect_output
from mlaunch.launch_testing.tools.text import build_line_match, build_text_match
from mlaunch.launch_testing.util import NO_CMD_ARGS, NoMatchingProcessException, resolveProcesses


def test_text_match_string_regex_and_sequence() -> None:
    assert build_text_match("b c")("a b c d") == (2, 5)
    assert build_text_match(re.compile(r"c\s+d"))("a b c  d") == (4, 8)
    assert build_text_match(["a", "c"])("a b c") == (0, 5)
    assert build_text_match(["c", "a"])("a b c") is None  # in order only
    assert build_text_match("a b", strict=True)("a b") == (0, 3)
    assert build_text_match("a", strict=True)("a b") is None
    assert build_text_match("x\ny")("x\r\ny") == (0, 3)  # a pty's line endings
    with pytest.raises(ValueError, match="expected text"):
        build_text_match(42)


def test_line_match() -> None:
    lines = ["start", "loop 1", "loop 2", "end"]
    assert build_line_match("loop")(lines) == (1, 2)
    assert build_line_match(["loop 1", "end"])(lines) == (1, 4)
    assert build_line_match(["end", "loop 1"])(lines) is None
    assert expect_output(text="a\nb\n", expected_lines=["a", "b"])
    assert not expect_output(lines=["a"], expected_text="b")
    with pytest.raises(ValueError, match="not both"):
        expect_output(text="a", lines=["a"], expected_text="a")


def test_sequential_checker_moves_forward_only() -> None:
    checker = SequentialTextChecker(["one two\n", "three\n", "two again\n"])
    checker.assertInStdout("two")
    checker.assertInStdout("three")
    checker.assertInStdout("two")  # the later one
    with pytest.raises(AssertionError, match="'one' not found in sequence"):
        checker.assertInStdout("one")


def test_output_filter_drops_prefixes_and_patterns() -> None:
    keep = basic_output_filter(filtered_patterns=[r"debug:"])
    assert keep("pid 12\nhello\ndebug: x\nrc 0\nbye\n") == "hello\nbye\n"


def _started(action: ExecuteProcess, name: str, cmd: list[str]) -> None:
    action.process_details = {"name": name, "cmd": cmd, "cwd": None, "env": {}, "pid": 1}


def test_processes_by_action_by_name_and_by_arguments() -> None:
    talker, listener, bare = (ExecuteProcess(cmd=["x"]) for _ in range(3))
    _started(talker, "talker-1", ["talker", "--rate", "5"])
    _started(listener, "listener-2", ["listener", "--rate", "5"])
    _started(bare, "talker-3", ["talker"])
    output = IoHandler()
    for action in (talker, listener, bare):
        name = action.process_details["name"]  # type: ignore[index]
        output.append(ProcessIO(action=action, name=name, text=f"{name} up\n".encode(), fd=1))
    assert resolveProcesses(output, process=talker) == [talker]
    assert resolveProcesses(output, process="listener") == [listener]
    assert resolveProcesses(output, process="talker", cmd_args=NO_CMD_ARGS) == [bare]
    assert resolveProcesses(output, process="talker", cmd_args="--rate") == [talker]
    with pytest.raises(Exception, match="Found multiple processes matching name 'talker'"):
        resolveProcesses(output, process="talker")
    with pytest.raises(NoMatchingProcessException, match="Procs: "):
        resolveProcesses(output, process="nobody")
    with pytest.raises(TypeError, match="must be .ExecuteProcess. or .str. not"):
        resolveProcesses(output, process=3)
    assertInStdout(output, "listener-2 up", "listener")
    with pytest.raises(AssertionError, match="Did not find 'nope'"):
        assertInStdout(output, "nope", listener)


def test_exit_codes() -> None:
    info = ProcInfoHandler()
    ok, bad = ExecuteProcess(cmd=["x"]), ExecuteProcess(cmd=["y"])
    _started(ok, "ok-1", ["ok"])
    _started(bad, "bad-2", ["bad"])
    info.append(ProcessExited(action=ok, name="ok-1", returncode=0))
    info.append(ProcessExited(action=bad, name="bad-2", returncode=-2))
    assertExitCodes(info, process=ok)
    assertExitCodes(info, [-2], process="bad")
    with pytest.raises(AssertionError, match="Proc bad-2 exited with code -2"):
        assertExitCodes(info)


def test_parametrize_yields_one_description_per_value() -> None:
    @parametrize("word, count", [("a", 1), ("b", 2)])
    def generate_test_description(word: str, count: int) -> tuple[str, int]:
        return word, count

    runs = list(generate_test_description())
    assert [args for _, args in runs] == [{"word": "a", "count": 1}, {"word": "b", "count": 2}]
    assert [function() for function, _ in runs] == [("a", 1), ("b", 2)]

    @parametrize("a, b", [(1,)])
    def wrong(a: int, b: int) -> None:
        return None

    with pytest.raises(ValueError, match="has 1 items, expected 2"):
        list(wrong())


def test_retry_on_failure_retries_assertions_only() -> None:
    calls: list[int] = []

    class Flaky(unittest.TestCase):
        @retry_on_failure(times=3)
        def test_third_time(self) -> None:
            calls.append(1)
            self.assertGreaterEqual(len(calls), 3)

    result = unittest.TestResult()
    Flaky("test_third_time").run(result)
    assert result.wasSuccessful() and len(calls) == 3
    with pytest.raises(ValueError, match="times is 0"):
        retry_on_failure(times=0)


def test_a_process_proxy_splits_what_a_prepared_process_printed_by_stream() -> None:
    from mlaunch.launch.events import ProcessStarted, ProcessStderr, ProcessStdout
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch_testing.io_handler import ActiveIoHandler
    from mlaunch.launch_testing.proc_info_handler import ActiveProcInfoHandler
    from mlaunch.launch_testing.tools import ProcessProxy

    output, info = ActiveIoHandler(), ActiveProcInfoHandler()
    action = ExecuteProcess(cmd=["ls", "-l"], name="lister")
    proxy = ProcessProxy(action, info, output)
    action.prepare(LaunchContext())
    facts = {"action": action, "name": action.name, "cmd": action.cmd, "pid": 7}
    assert not proxy.running and action.name.startswith("lister-")
    info.append(ProcessStarted(**facts))
    output.append(ProcessStdout(text=b"out\n", **facts))
    output.append(ProcessStderr(text=b"err\n", **facts))
    assert proxy.running and not proxy.terminated
    assert (proxy.stdout, proxy.stderr, proxy.output) == ("out\n", "err\n", "out\nerr\n")
