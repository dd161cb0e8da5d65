"""launch_testing files under ``mlaunch test`` / ``launch_test``: the same per-test results as the
reference launch_test (recorded in tests/launch_testing/reference_results.json from its JUnit
reports; re-checked live where the reference is built on the machine)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import reference
from conftest import requires_rclpy
from procutil import REPO, clean_env, mlaunch

EXAMPLES = REPO / "tests" / "launch_testing"
RECORDED = json.loads((EXAMPLES / "reference_results.json").read_text())
UPSTREAM_EXAMPLES = reference.SOURCES / "launch/launch_testing/test/launch_testing/examples"
UPSTREAM_PROCESSES = reference.SOURCES / "launch/launch_testing/example_processes"
# What the upstream examples were run with (args_launch_test needs a non-default dut_arg).
UPSTREAM_ARGS = ["dut_arg:=hello"]
TIMEOUT = 120


def outcomes(report: Path) -> dict[str, str]:
    """{'suite::class.test': passed|failed|error|skipped} from a JUnit report."""
    found = {}
    for suite in ET.parse(report).getroot().iter("testsuite"):
        for case in suite.iter("testcase"):
            kind = "passed"
            for tag, name in (("failure", "failed"), ("error", "error"), ("skipped", "skipped")):
                if case.find(tag) is not None:
                    kind = name
            found[f"{suite.get('name')}::{case.get('classname')}.{case.get('name')}"] = kind
    return found


def run_launch_test(
    argv: list[str], report: Path, env: dict[str, str]
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*argv, "--junit-xml", str(report)],
        capture_output=True,
        text=True,
        env=env,
        timeout=TIMEOUT,
        stdin=subprocess.DEVNULL,
        cwd=report.parent,
    )


def expected_status(results: dict[str, str]) -> int:
    return 0 if all(v in ("passed", "skipped") for v in results.values()) else 1


@pytest.mark.parametrize("name", sorted(RECORDED["ours"]))
def test_our_examples_give_the_reference_results(name: str, tmp_path: Path) -> None:
    report = tmp_path / "report.xml"
    done = run_launch_test(mlaunch("test", str(EXAMPLES / name)), report, clean_env())
    expected = RECORDED["ours"][name]
    assert report.exists(), done.stdout + done.stderr
    assert outcomes(report) == expected, done.stdout + done.stderr
    assert done.returncode == expected_status(expected), done.stdout + done.stderr


def test_report_has_launch_testing_structure(tmp_path: Path) -> None:
    report = tmp_path / "report.xml"
    run_launch_test(mlaunch("test", str(EXAMPLES / "failing.test.py")), report, clean_env())
    root = ET.parse(report).getroot()
    assert root.tag == "testsuites"
    assert root.get("name") == "failing.test.failing.test"
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("5", "2", "0")
    (suite,) = list(root)
    assert suite.tag == "testsuite" and suite.get("skipped") == "1"
    failure = suite.find("testcase[@name='test_exit_zero']/failure")
    assert failure is not None and "Proc quitter-1 exited with code 3" in failure.get("message", "")


def test_launch_test_program_and_show_args(tmp_path: Path) -> None:
    program = Path(sys.executable).with_name("launch_test")
    if not program.exists():
        pytest.skip(f"{program} is not installed (pip install -e . makes it)")
    shown = subprocess.run(
        [str(program), str(EXAMPLES / "tools.test.py"), "--show-args"],
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=TIMEOUT,
    )
    assert shown.returncode == 0, shown.stderr
    assert "greeting" in shown.stdout and "'plain'" in shown.stdout
    report = tmp_path / "report.xml"
    done = run_launch_test(
        [str(program), str(EXAMPLES / "tools.test.py"), "greeting:=fancy"], report, clean_env()
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "hello fancy" in done.stdout + done.stderr


def test_not_a_launch_test_is_a_clear_error(tmp_path: Path) -> None:
    plain = tmp_path / "plain.py"
    plain.write_text("x = 1\n")
    done = subprocess.run(
        [sys.executable, "-m", "mlaunch.cli.launch_test", str(plain)],
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=TIMEOUT,
    )
    assert done.returncode == 2
    assert "must define generate_test_description()" in done.stderr


@requires_rclpy
def test_wait_for_topics_of_launch_testing_ros(tmp_path: Path, ros_env: dict[str, str]) -> None:
    """launch_testing_ros.WaitForTopics receives a launched node's messages (needs rclpy)."""
    report = tmp_path / "report.xml"
    name = "wait_for_topics.ros.py"
    done = run_launch_test(mlaunch("test", str(EXAMPLES / name)), report, clean_env(**ros_env))
    assert outcomes(report) == RECORDED["ros"][name], done.stdout + done.stderr
    assert done.returncode == 0


# --- the upstream examples (their sources come with the reference build) -------------------------


def _upstream_prefix(tmp_path: Path) -> Path:
    """An ament prefix with launch_testing's example processes in lib/launch_testing, where the
    upstream examples look for them."""
    prefix = tmp_path / "prefix"
    (prefix / "share/ament_index/resource_index/packages").mkdir(parents=True)
    (prefix / "share/ament_index/resource_index/packages/launch_testing").touch()
    (prefix / "share/launch_testing").mkdir()
    shutil.copytree(UPSTREAM_PROCESSES, prefix / "lib/launch_testing")
    return prefix


needs_upstream = pytest.mark.skipif(
    not UPSTREAM_EXAMPLES.is_dir(),
    reason=f"the upstream launch_testing examples are not at {UPSTREAM_EXAMPLES}: {reference.MISSING}",
)


@needs_upstream
@pytest.mark.parametrize("name", sorted(RECORDED["upstream_examples"]))
def test_upstream_examples_give_the_reference_results(name: str, tmp_path: Path) -> None:
    env = clean_env(AMENT_PREFIX_PATH=str(_upstream_prefix(tmp_path)))
    report = tmp_path / "report.xml"
    done = run_launch_test(
        mlaunch("test", str(UPSTREAM_EXAMPLES / name), *UPSTREAM_ARGS), report, env
    )
    expected = RECORDED["upstream_examples"][name]
    assert outcomes(report) == expected, done.stdout + done.stderr
    assert done.returncode == expected_status(expected), done.stdout + done.stderr


@pytest.mark.skipif(not reference.ENV_SH.exists(), reason=reference.MISSING)
def test_recording_still_matches_the_live_reference(tmp_path: Path) -> None:
    """The recorded results are what the reference gives today (one file, to stay quick)."""
    report = tmp_path / "report.xml"
    script = f"source {reference.ENV_SH} && launch_test {EXAMPLES / 'failing.test.py'}"
    done = run_launch_test(["bash", "-c", f'{script} "$@"', "launch_test"], report, clean_env())
    assert outcomes(report) == RECORDED["ours"]["failing.test.py"], done.stdout + done.stderr
    assert done.returncode == 1


def test_examples_are_ours() -> None:
    """The shipped examples are written for mlaunch, not copies of upstream's files."""
    ours = {p.name for p in EXAMPLES.glob("*.test.py")}
    assert ours == set(RECORDED["ours"])
    if UPSTREAM_EXAMPLES.is_dir():
        theirs = {p.read_text() for p in UPSTREAM_EXAMPLES.glob("*.py")}
        assert not any(p.read_text() in theirs for p in EXAMPLES.glob("*.py"))


# --- a test file of a real ROS 2 package, unmodified -----------------------------------------------

DEMOS_GIT = Path("/work/.mirror/ros-controls+ros2_control_demos/repo")


def _ros2_control_demos(tmp_path: Path) -> Path | None:
    """A checkout of ros-controls/ros2_control_demos: $ROS2_CONTROL_DEMOS, or the git mirror."""
    given = os.environ.get("ROS2_CONTROL_DEMOS")
    if given:
        return Path(given)
    if not DEMOS_GIT.is_dir():
        return None
    archive = subprocess.run(
        [
            "git",
            "-C",
            str(DEMOS_GIT),
            "archive",
            "HEAD",
            "example_1",
            "ros2_control_demo_description",
        ],
        capture_output=True,
        check=True,
    )
    subprocess.run(["tar", "-x", "-C", str(tmp_path)], input=archive.stdout, check=True)
    return tmp_path


def _install_like(source: Path, prefix: Path) -> None:
    """The share folders colcon would install for example_1's description (CMakeLists' install)."""
    index = prefix / "share/ament_index/resource_index/packages"
    index.mkdir(parents=True)
    for package in ("ros2_control_demo_example_1", "ros2_control_demo_description"):
        (index / package).touch()
    share = prefix / "share/ros2_control_demo_example_1"
    for folder in ("launch", "ros2_control", "urdf"):
        shutil.copytree(source / "example_1/description" / folder, share / folder)
    shutil.copytree(
        source / "ros2_control_demo_description", prefix / "share/ros2_control_demo_description"
    )


def test_a_real_packages_launch_test_runs_unmodified(tmp_path: Path) -> None:
    """ros2_control_demos example_1's test_view_robot_launch.py: xacro, robot_state_publisher
    (mlaunch's stand-in here), ReadyToTest, no test cases; passes as under ROS 2."""
    source = _ros2_control_demos(tmp_path)
    if source is None:
        pytest.skip("no ros2_control_demos sources: set ROS2_CONTROL_DEMOS to a checkout")
    prefix = tmp_path / "install"
    _install_like(source, prefix)
    report = tmp_path / "report.xml"
    test_file = source / "example_1/test/test_view_robot_launch.py"
    done = run_launch_test(
        mlaunch("test", str(test_file)), report, clean_env(AMENT_PREFIX_PATH=str(prefix))
    )
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    assert "robot_state_publisher" in output and "process started" in output
    assert ET.parse(report).getroot().get("failures") == "0"
