"""CI builds the reference ros2 launch (scripts/reference, called by .ci/run) so the
differential tests compare instead of skipping (issue 38, item 18): built once per key in a
folder of its own, found by the tests through MLAUNCH_REFERENCE."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest
import reference
from procutil import REPO

SCRIPT = REPO / "scripts" / "reference"
# A stand-in for the reference's setup.sh: what the real one leaves (env.sh in ANCHOR_DIR), one
# line per build in builds.txt beside it, and a failure when FAIL is in the folder.
FAKE_SETUP = """\
#!/usr/bin/env bash
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
[[ "$1" == --archives ]]
echo "$ANCHOR_DIR" >> "$here/builds.txt"
[[ ! -e "$here/FAIL" ]] || { echo "pip: no such wheel"; exit 1; }
mkdir -p "$ANCHOR_DIR"
echo "export REFERENCE_BUILT=1" > "$ANCHOR_DIR/env.sh"
"""


@pytest.fixture
def tool(tmp_path: Path) -> Path:
    folder = tmp_path / "ros2-launch"
    (folder / "archives").mkdir(parents=True)
    (folder / "archives" / "VERSIONS").write_text("launch 3.4.3 abc\n")
    (folder / "runner.py").write_text("")
    (folder / "setup.sh").write_text(FAKE_SETUP)
    return folder


def build(tool: Path, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    return subprocess.run(
        [str(SCRIPT), str(tool / "setup.sh")], capture_output=True, text=True, env=env, timeout=60
    )


def test_the_reference_is_built_once_per_key_in_a_folder_of_its_own(
    tool: Path, tmp_path: Path
) -> None:
    first = build(tool, tmp_path)
    assert first.returncode == 0, first.stderr
    folder = Path(first.stdout.strip())
    assert folder.parent == tmp_path / "cache" / "mlaunch"
    assert folder.name.startswith("reference-")
    assert (folder / "env.sh").read_text() == "export REFERENCE_BUILT=1\n"
    again = build(tool, tmp_path)
    assert again.returncode == 0 and again.stdout == first.stdout, again.stderr
    assert (tool / "builds.txt").read_text().splitlines() == [str(folder)]  # cached
    (tool / "archives" / "VERSIONS").write_text("launch 3.4.4 def\n")  # new sources, new key
    other = build(tool, tmp_path)
    assert other.returncode == 0, other.stderr
    assert other.stdout != first.stdout
    assert len((tool / "builds.txt").read_text().splitlines()) == 2


def test_a_failed_build_says_why_and_is_tried_again(tool: Path, tmp_path: Path) -> None:
    (tool / "FAIL").touch()
    failed = build(tool, tmp_path)
    assert failed.returncode == 1
    assert "pip: no such wheel" in failed.stderr
    assert "building the reference ros2 launch failed" in failed.stderr
    (tool / "FAIL").unlink()
    done = build(tool, tmp_path)  # a half-made folder is not taken for a built one
    assert done.returncode == 0, done.stderr
    assert len((tool / "builds.txt").read_text().splitlines()) == 2


def test_ci_runs_the_differential_tests_where_it_built_the_reference() -> None:
    # .ci/run sets MLAUNCH_REFERENCE to what it built: then the tests that compare with the
    # reference must find it, not skip (before: 116 of them skipped on every CI machine).
    if not os.environ.get("MLAUNCH_REFERENCE"):
        pytest.skip("MLAUNCH_REFERENCE is not set (.ci/run sets it when it builds the reference)")
    assert reference.ENV_SH.is_file(), reference.MISSING
    assert (reference.SOURCES / "launch" / "launch_testing").is_dir(), reference.MISSING


def test_ci_builds_the_reference_before_the_suite() -> None:
    ci = (REPO / ".ci" / "run").read_text()
    assert 'scripts/reference "$reference_setup"' in ci
    assert ci.index("export MLAUNCH_REFERENCE") < ci.index("scripts/check")
