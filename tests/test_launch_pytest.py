"""launch_pytest fixtures and markers, and launch_testing files collected by pytest, through
mlaunch's pytest plugins: the same per-test results as under the reference (recorded in
tests/launch_pytest/reference_results.json from its JUnit reports)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import reference
from conftest import requires_rclpy
from procutil import REPO, clean_env

EXAMPLES = REPO / "tests" / "launch_pytest"
LAUNCH_TESTING = REPO / "tests" / "launch_testing"
RECORDED = json.loads((EXAMPLES / "reference_results.json").read_text())
UPSTREAM = reference.SOURCES / "launch/launch_pytest/test/launch_pytest"
TIMEOUT = 120


def run_pytest(path: Path, tmp_path: Path, env: dict[str, str]) -> tuple[list[list[str]], str]:
    """Run pytest on one file in its own process; ([name, outcome] sorted, its output)."""
    report = tmp_path / "report.xml"
    done = subprocess.run(
        [
            *(sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", str(path)),
            *("--junitxml", str(report), "-o", "addopts=", "--rootdir", str(path.parent)),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=TIMEOUT,
        stdin=subprocess.DEVNULL,
        cwd=path.parent,
    )
    output = done.stdout + done.stderr
    assert report.exists(), output
    found = []
    for case in ET.parse(report).getroot().iter("testcase"):
        kind = "passed"
        for tag, name in (("failure", "failed"), ("error", "error"), ("skipped", "skipped")):
            if case.find(tag) is not None:
                kind = name
        found.append([case.get("name", ""), kind])
    return sorted(found), output


@pytest.mark.parametrize("name", sorted(RECORDED["ours"]))
def test_our_launch_pytest_examples(name: str, tmp_path: Path) -> None:
    found, output = run_pytest(EXAMPLES / name, tmp_path, clean_env())
    assert found == RECORDED["ours"][name], output


@pytest.mark.parametrize("name", sorted(RECORDED["launch_testing_via_pytest"]))
def test_launch_testing_files_collected_by_pytest(name: str, tmp_path: Path) -> None:
    """A file marked @pytest.mark.launch_test is one pytest item running all its tests.

    Copied under an importable name: pytest cannot import ``counting.test.py`` (nor can the
    reference's plugin).
    """
    shutil.copy(LAUNCH_TESTING / "chatter.py", tmp_path / "chatter.py")
    source = LAUNCH_TESTING / name.replace("_launch.py", ".test.py")
    shutil.copy(source, tmp_path / name)
    found, output = run_pytest(tmp_path / name, tmp_path, clean_env())
    assert found == RECORDED["launch_testing_via_pytest"][name], output
    if found[0][1] == "failed":
        assert "test_never_printed" in output and "test_exit_zero" in output


needs_upstream = pytest.mark.skipif(
    not UPSTREAM.is_dir(),
    reason=f"the upstream launch_pytest examples are not at {UPSTREAM}: {reference.MISSING}",
)


def _upstream_copy(tmp_path: Path, name: str) -> Path:
    shutil.copytree(UPSTREAM / "examples", tmp_path / "examples")
    return tmp_path / "examples" / name


@needs_upstream
@pytest.mark.parametrize(
    "name", sorted(n for n in RECORDED["upstream_examples"] if n != "check_node_msgs.py")
)
def test_upstream_launch_pytest_examples(name: str, tmp_path: Path) -> None:
    found, output = run_pytest(_upstream_copy(tmp_path, name), tmp_path, clean_env())
    assert found == RECORDED["upstream_examples"][name], output


@needs_upstream
@requires_rclpy
def test_upstream_example_with_a_ros_node(tmp_path: Path, ros_env: dict[str, str]) -> None:
    """check_node_msgs: a launch_ros Node publishes, the test subscribes with rclpy."""
    path = _upstream_copy(tmp_path, "check_node_msgs.py")
    found, output = run_pytest(path, tmp_path, clean_env(**ros_env))
    assert found == RECORDED["upstream_examples"]["check_node_msgs.py"], output
