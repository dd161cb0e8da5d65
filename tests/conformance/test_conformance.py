"""The differential conformance suite: every case, run by mlaunch, does what ros2 launch does.

Each case in cases/ was run under the reference ros2 launch (Jazzy) and what it started was
recorded in expected/ (record.py). ``test_mlaunch_matches_reference`` runs mlaunch on the case
and compares; it needs no ROS, so CI runs it. ``test_recording_is_current`` runs the reference
itself where it is built and checks the recording still says what it does, so the recordings
cannot drift from the real thing. docs/conformance.md lists what is covered and every known
difference; KNOWN_DIFFERENCES below are those differences, each a strict xfail that turns into
a failure the day it is fixed (then delete the entry).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import harness
import pytest

KNOWN_DIFFERENCES: dict[str, str] = {
    "exit_status_required.launch.py": "on purpose: a failed required process exits 1 (README: exit status)",
}

REFERENCE = harness.reference_environ()
requires_reference = pytest.mark.skipif(
    REFERENCE is None,
    reason=f"{harness.reference.MISSING}; the recorded results are checked instead",
)


def _cases() -> list[Any]:
    return harness.with_known_differences(harness.case_names(), KNOWN_DIFFERENCES)


def _diff(expected: dict[str, Any], actual: dict[str, Any]) -> str:
    lines = []
    for key in sorted(set(expected) | set(actual)):
        if expected.get(key) != actual.get(key):
            lines.append(f"{key}:\n  ros2 launch: {json.dumps(expected.get(key), sort_keys=True)}")
            lines.append(f"  mlaunch:     {json.dumps(actual.get(key), sort_keys=True)}")
    return "\n".join(lines)


@pytest.mark.parametrize("case", _cases())
def test_mlaunch_matches_reference(case: str, tmp_path: Path) -> None:
    expected = harness.expected(case)
    assert expected is not None, f"no recording for {case}: run tests/conformance/record.py {case}"
    actual = harness.run_case("mlaunch", case, tmp_path, None)
    assert actual == expected, f"{case} differs from ros2 launch:\n{_diff(expected, actual)}"


@requires_reference
@pytest.mark.parametrize("case", harness.case_names())
def test_recording_is_current(case: str, tmp_path: Path) -> None:
    assert REFERENCE is not None
    actual = harness.run_case("ros2", case, tmp_path, REFERENCE)
    expected = harness.expected(case)
    assert actual == expected, (
        f"the reference no longer does what expected/{case}.json says; re-record it:\n"
        f"{_diff(expected or {}, actual)}"
    )


def test_every_recording_has_a_case() -> None:
    """A recording without a case file is a case that was renamed or deleted and left behind."""
    recorded = {p.name.removesuffix(".json") for p in harness.EXPECTED.glob("*.json")}
    assert recorded <= set(harness.case_names())
