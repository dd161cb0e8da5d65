"""Record what the reference ros2 launch does for each case into expected/NAME.json.

    .venv/bin/python tests/conformance/record.py [CASE ...]                # all cases when none are named
    .venv/bin/python tests/conformance/record.py --components [CASE ...]   # component_cases/ instead

Needs the reference built (tests/reference.py says where: scripts/reference builds it). The
recordings are what the conformance tests hold mlaunch to where the reference is absent (CI).
Component cases also need rclpy and the composition_interfaces ./scripts/setup builds; they run
in a ROS domain of their own.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import harness

sys.path.insert(0, str(harness.HERE.parent))  # tests/: ros_domain, procutil

import ros_domain


def main(names: list[str]) -> int:
    reference = harness.reference_environ()
    if reference is None:
        print(harness.reference.MISSING, file=sys.stderr)
        return 2
    if names[:1] == ["--components"]:
        return record_components(names[1:], reference)
    for name in names or harness.case_names():
        with tempfile.TemporaryDirectory() as work:
            summary = harness.run_case("ros2", name, Path(work), reference)
        harness.write_expected(name, summary)
        print(
            f"{name}: rc {summary['rc']}, {len(summary['processes'])} processes, {len(summary['log'])} log lines"
        )
    return 0


def record_components(names: list[str], reference: dict[str, str]) -> int:
    import components

    with ros_domain.private_domain() as domain:
        ros_env = {
            "ROS_DOMAIN_ID": str(domain),
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
            "RMW_IMPLEMENTATION": os.environ.get("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp"),
        }
        for name in names or components.case_names():
            with tempfile.TemporaryDirectory() as work:
                summary = components.run_case("ros2", name, Path(work), reference, ros_env)
            components.write_expected(name, summary)
            counts = {c: len(r) for c, r in summary["loads"].items()}
            print(f"{name}: requests per container {counts}, {len(summary['log'])} log lines")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
