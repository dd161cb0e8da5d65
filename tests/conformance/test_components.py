"""The differential suite for composable nodes: mlaunch sends the LoadNode requests ros2 launch sends.

Each case in component_cases/ was run under the reference ros2 launch (Jazzy) against recording
containers, and every request they received, and the launcher's log of each answer, was
recorded in component_expected/ (``record.py --components``). ``test_mlaunch_matches_reference``
runs mlaunch on the case against the same containers and compares; it needs rclpy and the
composition_interfaces ./scripts/setup builds, not the reference, so CI runs it.
``test_recording_is_current`` re-runs the reference where it is built, so the recordings cannot
drift from the real thing. Every run has its own ROS domain (the ``ros_env`` fixture).
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import components
import harness
import pytest
from conftest import requires_rclpy

# Cases whose log lines differ from the reference's on purpose; their requests must still match.
KNOWN_DIFFERENCES: dict[str, str] = {
    "ghost.launch.py": "on purpose: at shutdown mlaunch says which loads it abandoned, one line"
    " each (launch_ros says it once, for the first, naming only the service)",
}

REFERENCE = harness.reference_environ()
requires_reference = pytest.mark.skipif(
    REFERENCE is None,
    reason=f"{harness.reference.MISSING}; the recorded requests are checked instead",
)
requires_composition_interfaces = pytest.mark.skipif(
    importlib.util.find_spec("composition_interfaces") is None,
    reason="composition_interfaces is not built: run ./scripts/setup (it builds the interfaces)",
)
pytestmark = [requires_rclpy, requires_composition_interfaces, pytest.mark.timeout(150)]


class LogDifference(Exception):
    """The launcher's log lines differ from the reference's (the requests matched)."""


def _cases() -> list[Any]:
    return harness.with_known_differences(
        components.case_names(), KNOWN_DIFFERENCES, raises=LogDifference
    )


def _diff(expected: dict[str, Any], actual: dict[str, Any]) -> str:
    lines = []
    containers = sorted(set(expected.get("loads", {})) | set(actual.get("loads", {})))
    for container in containers:
        want = expected.get("loads", {}).get(container, [])
        got = actual.get("loads", {}).get(container, [])
        for i in range(max(len(want), len(got))):
            a = want[i] if i < len(want) else None
            b = got[i] if i < len(got) else None
            if a != b:
                lines.append(f"{container} request {i + 1}:")
                lines.append(f"  ros2 launch: {json.dumps(a, sort_keys=True)}")
                lines.append(f"  mlaunch:     {json.dumps(b, sort_keys=True)}")
    if expected.get("log") != actual.get("log"):
        lines.append(
            f"log:\n  ros2 launch: {expected.get('log')}\n  mlaunch:     {actual.get('log')}"
        )
    return "\n".join(lines)


@pytest.mark.parametrize("case", _cases())
def test_mlaunch_matches_reference(case: str, tmp_path: Path, ros_env: dict[str, str]) -> None:
    expected = components.expected(case)
    assert expected is not None, (
        f"no recording for {case}: run tests/conformance/record.py --components {case}"
    )
    actual = components.run_case("mlaunch", case, tmp_path, None, ros_env)
    assert actual["loads"] == expected["loads"], (
        f"{case}: the requests differ from ros2 launch's:\n{_diff(expected, actual)}"
    )
    if actual != expected:
        raise LogDifference(f"{case} logs otherwise than ros2 launch:\n{_diff(expected, actual)}")


@requires_reference
@pytest.mark.parametrize("case", components.case_names())
def test_recording_is_current(case: str, tmp_path: Path, ros_env: dict[str, str]) -> None:
    assert REFERENCE is not None
    actual = components.run_case("ros2", case, tmp_path, REFERENCE, ros_env)
    expected = components.expected(case)
    assert actual == expected, (
        f"the reference no longer sends what component_expected/{case}.json says; re-record it:\n"
        f"{_diff(expected or {}, actual)}"
    )


def test_every_recording_has_a_case() -> None:
    recorded = {p.name.removesuffix(".json") for p in components.EXPECTED.glob("*.json")}
    assert recorded <= set(components.case_names())
