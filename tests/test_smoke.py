"""`mlaunch test`: expectation parsing, the JUnit report, plain-process smoke runs, and the
tests/launches/smoke_system system (two lifecycle nodes and a talker) passing and failing."""

from __future__ import annotations

import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import clean_env, mlaunch, run_mlaunch

from mlaunch.commands.smoke import build_expectations, junit
from mlaunch.launch.actions import (
    ExecuteProcess,
    LaunchDescription,
    SetLaunchConfiguration,
)
from mlaunch.plan.errors import LaunchFileError, UsageError
from mlaunch.resolve.resolver import resolve
from mlaunch.smoke.expectations import Expect, _CollectConfigurations, parse_spec, parse_target
from mlaunch.smoke.settings import Settings, parse_settings, split_arguments

LAUNCHES = Path(__file__).resolve().parent / "launches"
SYSTEM = str(LAUNCHES / "smoke_system.launch.py")


# --- parsing -----------------------------------------------------------------------------------


def test_expectation_forms() -> None:
    topic = parse_spec("topic scan:10 within 15", "here")
    assert (topic.kind, topic.target, topic.rate, topic.within) == ("topic", "/scan", 10.0, 15.0)
    assert parse_target("topic", "/a/b", "x").rate is None
    life = parse_target("lifecycle", "/r/cam:inactive", "x")
    assert (life.target, life.state) == ("/r/cam", "inactive")
    assert parse_target("lifecycle", "/r/cam", "x").state == "active"
    out = parse_spec("output talker:Hello World: \\d+ within 2.5s", "x")
    assert (out.kind, out.target, out.within) == ("output", "talker:Hello World: \\d+", 2.5)
    assert parse_spec("service /map_server/load_map", "x").target == "/map_server/load_map"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("topics /scan", "is not 'KIND TARGET [within SECONDS]'"),
        ("topic", "is not 'KIND TARGET"),
        ("topic /scan:fast", "rate 'fast' is not a positive number of Hz"),
        ("topic /scan:-1", "rate '-1' is not a positive number"),
        ("lifecycle /cam:running", "state 'running' is not one of unconfigured, inactive"),
        ("node /a b", "node name '/a b'"),
    ],
)
def test_bad_expectations_say_what_is_valid(text: str, message: str) -> None:
    with pytest.raises(UsageError, match=message.replace("[", r"\[")):
        parse_spec(text, "--expect")


def test_command_line_options_are_split_from_mlaunchs_own() -> None:
    mine, rest = split_arguments(
        ["f.launch.py", "a:=1", "--expect-topic", "/x:5", "--within=3", "-d", "--hold", "2"]
    )
    assert rest == ["f.launch.py", "a:=1", "-d"]
    settings = parse_settings(mine)
    (topic,) = settings.expectations
    assert (topic.target, topic.rate, topic.within, settings.hold) == ("/x", 5.0, 3.0, 2.0)
    with pytest.raises(UsageError, match="--within S follows an --expect"):
        parse_settings(["--within", "3"])
    with pytest.raises(UsageError, match="--timeout 0"):
        parse_settings(["--timeout", "0"])
    with pytest.raises(UsageError, match="--expect-node needs a value"):
        split_arguments(["f.py", "--expect-node"])


def test_defaults_launch_file_expectations_and_overrides() -> None:
    """Defaults come from the plan; Expect actions and mlaunch_expect_* configurations add to
    them; the command line wins over the same check."""
    from mlaunch.launch_ros.actions import LifecycleNode, Node, SetParameter

    collector = _CollectConfigurations()
    ld = LaunchDescription(
        [
            SetParameter(name="use_sim_time", value=True),
            ExecuteProcess(cmd=[sys.executable, "-c", "pass"], name="worker"),
            Node(executable=sys.executable, name="talker", namespace="r"),
            LifecycleNode(executable=sys.executable, name="cam", namespace="r"),
            Expect(topic="/r/chatter", rate=5.0, within=4),
            SetLaunchConfiguration("mlaunch_expect_svc", "service /r/cam/get_state"),
            collector,
        ]
    )
    plan = resolve(ld, path=None, arguments={}, environ={})
    cli = [parse_target("lifecycle", "/r/cam:inactive", "cli")]
    found = build_expectations(plan, Settings(expectations=cli), collector, False)
    described = {e.describe(): e for e in found}
    labels = [s.label for s in plan.processes()]
    assert labels[0] == "worker-1" and len(labels) == 3
    assert set(described) == {
        *(f"process {label} starts and keeps running" for label in labels),
        "node /r/talker is in the ROS graph",
        "node /r/cam is in the ROS graph",
        "lifecycle node /r/cam is inactive",
        "/clock advances (use_sim_time)",
        "topic /r/chatter publishes at 5 Hz",
        "service /r/cam/get_state is offered",
        "every process stops within its stop ladder (no SIGKILL)",
    }
    assert described["topic /r/chatter publishes at 5 Hz"].within == 4
    assert described["lifecycle node /r/cam is inactive"].origin == "cli"


def test_expect_action_needs_exactly_one_target() -> None:
    with pytest.raises(LaunchFileError, match="exactly one of topic=.*got topic, node"):
        Expect(topic="/a", node="/b")
    with pytest.raises(LaunchFileError, match="got none"):
        Expect()


def test_junit_report_is_valid_xml_without_control_characters() -> None:
    cases = [
        junit.Case("node /a is in the ROS graph", "mlaunch.test.sys", 1.5),
        junit.Case(
            "topic /b publishes",
            "mlaunch.test.sys",
            9.0,
            failure="no message received",
            details="expected: topic /b publishes",
            system_out="--- last output of b-1 ---\n\x1b[31mboom\x1b[0m \x00\x07",
        ),
        junit.Case("output matches", "mlaunch.test.sys", skipped="undecided"),
    ]
    root = ET.fromstring(junit.render("mlaunch test sys.launch.py", cases, duration=10.0))
    suite = root.find("testsuite")
    assert suite is not None
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("3", "1", "1")
    failure = suite.find("testcase[@name='topic /b publishes']/failure")
    assert failure is not None and failure.get("message") == "no message received"
    out = suite.find("testcase[@name='topic /b publishes']/system-out")
    assert out is not None and out.text == "--- last output of b-1 ---\nboom \ufffd\ufffd"


# --- plain processes (no ROS: rclpy is never imported) -----------------------------------------

PLAIN = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess
from mlaunch.commands.smoke import Expect

PY = sys.executable


def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(
            cmd=[PY, "-u", "-c", "import time\\nfor i in range(1000):\\n    print('tick', i)\\n    time.sleep(0.05)"],
            name="ticker",
        ),
        ExecuteProcess(
            cmd=[PY, "-u", "-c", "import time, sys; print('warming up'); time.sleep(%(die)s); print('bye'); sys.exit(4)"],
            name="worker",
        ),
        ExecuteProcess(cmd=[PY, "-c", "print('done')"], name="oneshot"),
        Expect(output="ticker:tick 20$"),
    ])
"""


def _plain(tmp_path: Path, die: float) -> str:
    path = tmp_path / "plain.launch.py"
    path.write_text(PLAIN % {"die": die})
    return str(path)


def test_plain_run_passes_and_never_imports_rclpy(tmp_path: Path) -> None:
    report = tmp_path / "report.xml"
    done = subprocess.run(
        [
            sys.executable,
            "-X",
            "importtime",
            *mlaunch("test", _plain(tmp_path, 60), "--allow-exit", "oneshot")[1:],
            "--expect-output",
            "warming",
            "--junit",
            str(report),
        ],
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=60,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "rclpy" not in done.stderr
    assert "mlaunch test PASSED" in done.stdout
    assert "output of ticker matches /tick 20$/" in done.stdout
    assert "ticker-1: tick 20" in done.stdout
    suite = ET.parse(report).getroot().find("testsuite")
    assert suite is not None and suite.get("failures") == "0"
    assert suite.get("tests") == "6"  # three processes, two outputs, the clean stop


def test_early_exit_fails_with_status_and_last_output(tmp_path: Path) -> None:
    report = tmp_path / "report.xml"
    done = run_mlaunch(
        "test",
        _plain(tmp_path, 0.3),
        "--allow-exit",
        "oneshot",
        "--junit",
        str(report),
        env=clean_env(),
    )
    assert done.returncode == 1, done.stdout + done.stderr
    row = _row(done.stdout, "process worker-2")
    assert row.startswith("FAIL")
    assert "exited with status 4 after" in row and "before the launch was ready" in row
    assert "last output of worker-2:\n  | warming up\n  | bye\n" in done.stdout
    case = (
        ET.parse(report)
        .getroot()
        .find("testsuite/testcase[@name='process worker-2 starts and keeps running']")
    )
    assert case is not None
    failure, out = case.find("failure"), case.find("system-out")
    assert failure is not None and "exited with status 4" in (failure.get("message") or "")
    assert out is not None and "bye" in (out.text or "")


def test_hold_catches_a_crash_after_ready_and_deadline_fails_output(tmp_path: Path) -> None:
    held = run_mlaunch(
        "test", _plain(tmp_path, 1.5), "--allow-exit", "oneshot", "--hold", "5", env=clean_env()
    )
    assert held.returncode == 1, held.stdout + held.stderr
    assert "holding for 5 s" in held.stdout
    assert "exited with status 4 after" in held.stdout
    # A process that exits 0 and is not respawned is a one-shot, fine without --allow-exit; an
    # output never printed fails at its own deadline with what was looked for.
    missed = run_mlaunch(
        "test",
        _plain(tmp_path, 60),
        "--expect-output",
        "worker:never printed",
        "--within",
        "1.5",
        env=clean_env(),
    )
    assert missed.returncode == 1
    oneshot = _row(missed.stdout, "process oneshot-3")
    assert oneshot.startswith("ok") and "a one-shot, finished" in oneshot, missed.stdout
    assert _row(missed.stdout, "output of worker").startswith("FAIL"), missed.stdout


RESPAWNER = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

PY = sys.executable


def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[PY, "-c", "import time; time.sleep(60)"], name="steady"),
        ExecuteProcess(
            cmd=[PY, "-c", "import time; time.sleep(0.5)"], name="looper", respawn=True,
            respawn_delay=0.2,
        ),
    ])
"""


def test_default_hold_catches_a_late_crash_and_a_respawning_exit_fails(tmp_path: Path) -> None:
    # No --hold: the default hold (3 s) still sees the worker die 2 s after it started.
    late = run_mlaunch("test", _plain(tmp_path, 2.0), env=clean_env())
    assert late.returncode == 1, late.stdout + late.stderr
    assert "holding for 3 s" in late.stdout
    assert "exited with status 4 after" in _row(late.stdout, "process worker-2")
    # A process started with respawn that exits fails, even with status 0.
    path = tmp_path / "respawn.launch.py"
    path.write_text(RESPAWNER)
    done = run_mlaunch("test", str(path), "--hold", "2", env=clean_env())
    assert done.returncode == 1, done.stdout + done.stderr
    row = _row(done.stdout, "process looper-2")
    assert row.startswith("FAIL") and "exited with status 0" in row, done.stdout
    assert _row(done.stdout, "process steady-1").startswith("ok")


def test_bad_options_are_one_line_errors(tmp_path: Path) -> None:
    done = run_mlaunch("test", _plain(tmp_path, 60), "--expect", "topic /a:x", env=clean_env())
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "mlaunch: error: topic expectation '/a:x' (--expect 'topic /a:x'): rate 'x' is not a"
        " positive number of Hz (write /scan:10)"
    ]
    bare = run_mlaunch("test", env=clean_env())
    assert bare.returncode == 2
    assert bare.stderr.strip() == (
        "mlaunch: error: a launch file is needed: mlaunch test FILE [name:=value ...]"
    )


# --- the ROS system ------------------------------------------------------------------------------


def _summary(out: str) -> str:
    """The summary table mlaunch test prints last."""
    return out[out.rindex("\nmlaunch test ") :]


def _row(out: str, text: str) -> str:
    """The summary row (stripped) whose expectation contains text."""
    return next(line.strip() for line in _summary(out).splitlines() if text in line)


def _table(out: str) -> dict[str, str]:
    """expected -> status of each row of the summary table."""
    rows = {}
    for line in _summary(out).splitlines()[3:]:
        if not line.startswith("  ") or line.startswith("  |"):
            continue
        parts = line.split(None, 2)
        if len(parts) == 3:
            rows[parts[2]] = parts[0]
    return rows


def _smoke(ros_env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return run_mlaunch("test", *args, env=clean_env(**ros_env), timeout=45)


@requires_rclpy
def test_system_passes_with_lifecycle_nodes_brought_up_in_order(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    report = tmp_path / "junit.xml"
    done = _smoke(
        ros_env, SYSTEM, "--expect-service", "/robot/lidar/get_state", "--junit", str(report)
    )
    out = done.stdout
    assert done.returncode == 0, out + done.stderr
    assert "mlaunch test PASSED" in out
    # The sequence: the lidar is configured only once the camera is active; and the nodes are
    # deactivated in reverse before the launch stops.
    order = [
        out.index("activate of /robot/camera succeeded"),
        out.index("configure of /robot/lidar succeeded"),
        out.index("activate of /robot/lidar succeeded"),
        out.index("shutting down: mlaunch test: ready"),
        out.index("deactivate of /robot/lidar succeeded"),
        out.index("deactivate of /robot/camera succeeded"),
    ]
    assert order == sorted(order), out
    suite = ET.parse(report).getroot().find("testsuite")
    assert suite is not None
    assert (suite.get("tests"), suite.get("failures")) == ("12", "0")


@requires_rclpy
@pytest.mark.parametrize(
    ("args", "failed", "seen"),
    [
        (
            ["variant:=crash"],
            "process lidar-2 starts and keeps running",
            r"exited with status 3 after [\d.]+ s \(pid \d+\), before the launch was ready",
        ),
        (
            # The deadline of this one check only: the others keep the default 30 s, so a
            # loaded machine starting the rest slowly cannot fail them first. 10 s, not 6: with
            # the suite on several workers, no node at all was in the graph after 6 s once.
            ["variant:=ghost", "--expect-node", "/robot/ghost", "--within", "10"],
            "node /robot/ghost is in the ROS graph",
            r"not in the graph \(nodes seen: [/a-z, ]*/robot/camera[/a-z, ]*\)"
            r" \(deadline 10 s passed\)",
        ),
        (
            ["variant:=silent", "--expect-topic", "/robot/chatter:10", "--within", "10"],
            "topic /robot/chatter publishes at 10 Hz",
            r"in the graph \(std_msgs/msg/String\) but no message received \(deadline 10 s passed\)",
        ),
        (
            ["variant:=fail_configure"],
            "lifecycle node /robot/lidar is active",
            r"configure of /robot/lidar failed: the node answered success=false;"
            r" it is now 'unconfigured'",
        ),
    ],
    ids=["crash", "ghost", "silent", "fail_configure"],
)
def test_system_fails_precisely(
    ros_env: dict[str, str], args: list[str], failed: str, seen: str
) -> None:
    done = _smoke(ros_env, SYSTEM, *args)
    out = done.stdout
    assert done.returncode == 1, out + done.stderr
    rows = _table(out)
    assert [row for row, status in rows.items() if status == "FAIL"] == [
        next(r for r in rows if r.startswith(failed))
    ], out
    line = _row(out, failed)
    assert line.startswith("FAIL") and re.search(seen, line), line
    assert rows[next(r for r in rows if r.startswith("every process stops"))] == "ok"


@requires_rclpy
@pytest.mark.serial  # a measured rate of 2-3 Hz
def test_yaml_system_declares_its_expectations_and_sequence(ros_env: dict[str, str]) -> None:
    yaml_file = str(LAUNCHES / "smoke_system.launch.yaml")
    done = _smoke(ros_env, yaml_file, f"python:={sys.executable}")
    out = done.stdout
    assert done.returncode == 0, out + done.stderr
    assert "output of lidar matches /^transition activate: success$/" in out
    assert out.index("activate of /robot/camera succeeded") < out.index(
        "configure of /robot/lidar succeeded"
    )
    slow = _smoke(
        ros_env,
        yaml_file,
        f"python:={sys.executable}",
        "rate:=3",
        # 10 s: the verdict needs 10 messages (3.3 s at 3 Hz) after a start that takes seconds
        # on a loaded machine; with fewer it is "too little data", not "too slow".
        *("--expect-topic", "/robot/chatter:10", "--within", "10"),
    )
    assert slow.returncode == 1
    line = _row(slow.stdout, "topic /robot/chatter")
    assert line.startswith("FAIL")
    assert re.search(r"too slow: [23]\.\d Hz over [12]\.\d s \(\d messages\)", line), line
    assert "wanted >= 9.0 Hz" in line


@requires_rclpy
def test_use_sim_time_waits_for_clock_to_advance(ros_env: dict[str, str]) -> None:
    clock_launch = str(LAUNCHES / "sim_clock.launch.py")
    done = _smoke(ros_env, clock_launch, "use_sim_time:=true")
    assert done.returncode == 0, done.stdout + done.stderr
    # Simulated seconds (sim_clock.py starts at 100 s, 50 ticks of 20 ms a second), not the wall
    # clock's: where in them the check starts depends on how long discovery took.
    row = _row(done.stdout, "/clock")
    advanced = re.search(r"advanced from (\d+\.\d\d) s to (\d+\.\d\d) s", row)
    assert advanced, row
    first, last = float(advanced.group(1)), float(advanced.group(2))
    assert 100.0 <= first < last < 200.0, row
    frozen = _smoke(
        ros_env,
        clock_launch,
        "use_sim_time:=true",
        "frozen:=true",
        "--expect",
        "clock /clock within 5",
    )
    assert frozen.returncode == 1
    row = _row(frozen.stdout, "/clock advances")
    assert row.startswith("FAIL") and re.search(r"stuck at 100\.00 s \(\d+ messages\)", row), row
