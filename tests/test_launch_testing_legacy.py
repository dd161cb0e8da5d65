"""launch_testing.legacy: LaunchTestService's verdicts on test processes, fixture processes and
output tests, and its bytes output filter."""

from __future__ import annotations

import sys
from pathlib import Path

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import ExecuteProcess, LaunchDescription
from mlaunch.launch_testing.legacy import LaunchTestService
from mlaunch.launch_testing.legacy.output import (
    create_output_lines_filter,
    create_output_lines_test,
    create_output_test_from_file,
)

# Prints two lines, then waits to be stopped (SIGINT ends it with status 0).
TALKER = (
    "import signal, sys, time\n"
    "signal.signal(signal.SIGINT, lambda *_: sys.exit(0))\n"
    "print('this is line 1', flush=True)\n"
    "print('this is line b', flush=True)\n"
    "time.sleep(60)\n"
)


def python(code: str) -> ExecuteProcess:
    return ExecuteProcess(cmd=[sys.executable, "-c", code])


def run(service: LaunchTestService, description: LaunchDescription) -> int:
    launch = LaunchService(screen=lambda data: None)
    launch.include_launch_description(description)
    return service.run(launch)


def test_test_processes_give_the_verdict() -> None:
    service, description = LaunchTestService(), LaunchDescription()
    service.add_test_action(description, python("pass"))
    assert run(service, description) == 0
    service, description = LaunchTestService(), LaunchDescription()
    service.add_test_action(description, python("import sys; sys.exit(3)"))
    service.add_test_action(description, python("import time; time.sleep(60)"))
    assert run(service, description) == 3  # the failure ends the launch: no 60 s wait


def test_a_fixture_dying_fails_the_run_with_its_code() -> None:
    service, description = LaunchTestService(), LaunchDescription()
    service.add_fixture_action(description, python("import sys; sys.exit(4)"))
    service.add_test_action(description, python("import time; time.sleep(60)"))
    assert run(service, description) == 4


def test_output_tests_end_the_launch_once_matched_and_never_fail_it(tmp_path: Path) -> None:
    (tmp_path / "expected.regex").write_text(r"this is line \d" + "\n" + "this is line [a-z]")
    service, description = LaunchTestService(), LaunchDescription()
    talker = service.add_fixture_action(description, python(TALKER))
    service.add_output_test(
        description, talker, create_output_test_from_file(str(tmp_path / "expected"))
    )
    assert run(service, description) == 0  # matched: the launch shuts down, talker exits 0

    # Unmatched output: the test finishes when its process exits, and the shutdown marks it
    # succeeded, as launch_testing does (only exit codes fail a legacy run).
    service, description = LaunchTestService(), LaunchDescription()
    printer = service.add_fixture_action(description, python("print('something else')"))
    service.add_output_test(description, printer, create_output_lines_test([b"this is line 1"]))
    assert run(service, description) == 0
    service, description = LaunchTestService(), LaunchDescription()
    failing = service.add_fixture_action(description, python("import sys; sys.exit(5)"))
    service.add_output_test(description, failing, create_output_lines_test([b"never"]))
    assert run(service, description) == 5


def test_bytes_filter_drops_prefixes_and_patterns_on_every_line() -> None:
    keep = create_output_lines_filter(filtered_patterns=[rb"\[dds\].*"])
    # A trailing line end is added back after the join, as launch_testing does (so it doubles);
    # launch_testing checks the patterns on the first line only (it keeps them in a map()
    # iterator): here every line is checked.
    assert keep(b"pid 3\nhello\n[dds] chatter\nbye\n") == b"hello\nbye\n\n"
    assert keep(b"a\nrc 1") == b"a"
