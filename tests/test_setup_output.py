"""``scripts/setup`` ends with one line that says it is ready and what to run next (issue 27,
item 18); the build backend's deprecation box for the compat editable mode is not shown."""

from __future__ import annotations

import hashlib
import subprocess

import pytest
from procutil import REPO, clean_env


def _up_to_date() -> bool:
    """Whether setup would reinstall nothing (its stamp matches): then it runs in a second."""
    want = b"".join((REPO / f).read_bytes() for f in ("pyproject.toml", "constraints.txt"))
    want += (REPO / "scripts" / "setup").read_bytes()
    stamp = REPO / ".venv" / ".mlaunch-installed"
    digest = hashlib.sha256(want).hexdigest()
    return stamp.exists() and stamp.read_text().strip() == digest


def test_setup_ends_with_a_ready_line_saying_what_to_run_next() -> None:
    if not _up_to_date():
        pytest.skip("the venv is older than scripts/setup: run it first (it would reinstall)")
    done = subprocess.run(
        [str(REPO / "scripts" / "setup")],
        capture_output=True,
        text=True,
        env=clean_env(),
        cwd=REPO,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    last = done.stdout.strip().splitlines()[-1]
    assert last.startswith("setup: ready. Next: .venv/bin/mlaunch launches/jtbot_sim.launch.py")
    assert "scripts/check runs the tests" in last
    assert "!!" not in done.stdout + done.stderr  # setuptools' box
