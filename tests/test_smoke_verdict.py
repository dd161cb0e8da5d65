"""`mlaunch test`'s verdict: a process that fails at any time of the run (before ready, in the
hold, in the shutdown), a required one included, fails the test, unless --allow-exit lets it."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

from mlaunch.plan.errors import UsageError
from mlaunch.smoke.settings import parse_allow_exit, parse_settings

# driver is required (on_exit=Shutdown()): it ends the launch one second in, after ready,
# the way %(end)s says; steady runs until it is stopped.
REQUIRED = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess, Shutdown

PY = sys.executable


def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(
            cmd=[PY, "-c", "import os, signal, sys, time; time.sleep(1); %(end)s"],
            name="driver", on_exit=Shutdown(),
        ),
        ExecuteProcess(cmd=[PY, "-c", "import time; time.sleep(60)"], name="steady"),
    ])
"""
EXIT_3 = "sys.exit(3)"
SEGFAULT = "os.kill(os.getpid(), signal.SIGSEGV)"
# A process that answers the stop signal with a failure status of its own.
BAD_STOP = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

PY = sys.executable
CODE = "import signal, sys, time\\nsignal.signal(signal.SIGINT, lambda *_: sys.exit(5))\\ntime.sleep(60)"


def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=[PY, "-c", CODE], name="grumpy")])
"""


def _launch(tmp_path: Path, text: str, **values: str) -> str:
    path = tmp_path / "smoke.launch.py"
    path.write_text(text % values if values else text)
    return str(path)


def _row(out: str, text: str) -> str:
    table = out[out.rindex("\nmlaunch test ") :]
    return next(line.strip() for line in table.splitlines() if text in line)


def _failures(report: Path) -> str | None:
    suite = ET.parse(report).getroot().find("testsuite")
    assert suite is not None
    return suite.get("failures")


@pytest.mark.parametrize(
    ("end", "how"), [(EXIT_3, "exited with status 3"), (SEGFAULT, "killed by SIGSEGV")]
)
def test_a_required_process_that_crashes_in_the_hold_fails(
    tmp_path: Path, end: str, how: str
) -> None:
    report = tmp_path / "report.xml"
    launch = _launch(tmp_path, REQUIRED, end=end)
    done = run_mlaunch("test", launch, "--hold", "10", "--junit", str(report), env=clean_env())
    assert done.returncode == 1, done.stdout + done.stderr
    assert "mlaunch test FAILED (1 of 3)" in done.stdout
    row = _row(done.stdout, "process driver-1")
    assert row.startswith("FAIL") and how in row and "during the hold" in row, done.stdout
    assert _row(done.stdout, "process steady-2").startswith("ok")
    assert _failures(report) == "1"


def test_allow_exit_with_codes_lets_a_crash_pass(tmp_path: Path) -> None:
    launch = _launch(tmp_path, REQUIRED, end=SEGFAULT)
    args = ("test", launch, "--hold", "10")
    allowed = run_mlaunch(*args, "--allow-exit", "driver:3,SIGSEGV", env=clean_env())
    assert allowed.returncode == 0, allowed.stdout + allowed.stderr
    assert "allowed by --allow-exit" in _row(allowed.stdout, "process driver-1")
    # Without CODES only status 0 is allowed: the segfault still fails.
    status_0 = run_mlaunch(*args, "--allow-exit", "driver", env=clean_env())
    assert status_0.returncode == 1, status_0.stdout


def test_a_failure_status_in_answer_to_the_stop_signal_fails(tmp_path: Path) -> None:
    report = tmp_path / "report.xml"
    launch = _launch(tmp_path, BAD_STOP)
    done = run_mlaunch("test", launch, "--hold", "0", "--junit", str(report), env=clean_env())
    assert done.returncode == 1, done.stdout + done.stderr
    row = _row(done.stdout, "process grumpy-1")
    assert "exited with status 5" in row and "after mlaunch's SIGINT, in the shutdown" in row
    assert _failures(report) == "1"
    allowed = run_mlaunch(
        "test", launch, "--hold", "0", "--allow-exit", "grumpy:5", env=clean_env()
    )
    assert allowed.returncode == 0, allowed.stdout + allowed.stderr


def test_allow_exit_codes_are_parsed_and_checked() -> None:
    assert parse_allow_exit("talker") == ("talker", frozenset({0}))
    assert parse_allow_exit("talker:0,3,SIGSEGV,abrt") == ("talker", frozenset({0, 3, -11, -6}))
    assert parse_allow_exit("talker:any") == ("talker", None)
    with pytest.raises(UsageError, match=r"'FOO' is neither an exit status \(0-255\) nor"):
        parse_settings(["--allow-exit", "talker:3,FOO"])
    with pytest.raises(UsageError, match="a process label first"):
        parse_settings(["--allow-exit", ":3"])


@pytest.mark.parametrize("flag", ["--junit", "--junit-xml"])
def test_both_junit_flags_work_for_launch_files_and_launch_testing_files(
    tmp_path: Path, flag: str
) -> None:
    """--junit was for launch files and --junit-xml for launch_testing files: the other one
    failed with the main usage text. Both work for both, also as --flag=FILE."""
    from procutil import REPO

    launch = _launch(tmp_path, REQUIRED, end="sys.exit(0)")
    launch_test = str(REPO / "tests" / "launch_testing" / "failing.test.py")
    for path, status, more in ((launch, 0, ["--hold", "0"]), (launch_test, 1, [])):
        for form in ([flag, str(tmp_path / "a.xml")], [f"{flag}={tmp_path / 'b.xml'}"]):
            report = Path(form[-1].split("=")[-1])
            report.unlink(missing_ok=True)
            done = run_mlaunch("test", path, *more, *form, env=clean_env(), timeout=120)
            assert done.returncode == status, done.stdout + done.stderr
            assert ET.parse(report).getroot().tag == "testsuites", (path, form)


def test_a_long_label_keeps_the_table_s_seen_column() -> None:
    """A row whose expectation is wider than the column (a long label) pushed its seen cell
    right; it now goes on a line of its own, in the column."""
    from collections import deque

    from mlaunch.smoke.expectations import Expectation
    from mlaunch.smoke.report import Report

    short = Expectation("process", "rsp-1", status="met", seen="running", at=1.0)
    long = Expectation("process", "x" * 70 + "-2", status="met", seen="running too", at=1.5)
    table = Report("f.launch.py", [short, long], {"rsp-1": deque()}, 2.0).table().splitlines()
    header = next(line for line in table if line.rstrip().endswith("seen"))
    column = header.index("seen")
    assert table[-1].index("running too") == column, table
    assert table[-3].rindex("running") == column, table
