"""Record what the reference ros2 launch does for each case into expected/NAME.json.

    .venv/bin/python tests/conformance/record.py [CASE ...]    # all cases when none are named

Needs the reference built at ~/.cache/ros2-launch-jazzy (see /work/shared/tools/ros2-launch). The
recordings are what the conformance tests hold mlaunch to where the reference is absent (CI).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import harness


def main(names: list[str]) -> int:
    reference = harness.reference_environ()
    if reference is None:
        print(
            "the reference ros2 launch is not built (~/.cache/ros2-launch-jazzy)", file=sys.stderr
        )
        return 2
    for name in names or harness.case_names():
        with tempfile.TemporaryDirectory() as work:
            summary = harness.run_case("ros2", name, Path(work), reference)
        harness.write_expected(name, summary)
        print(
            f"{name}: rc {summary['rc']}, {len(summary['processes'])} processes, {len(summary['log'])} log lines"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
