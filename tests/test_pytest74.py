"""mlaunch's pytest plugins under pytest 7.4.4 (Ubuntu 24.04's python3-pytest, what ROS 2 Jazzy
runs), not only under the venv's current pytest.

pytest 7.4.4 and what it needs are installed once with pip into a cache folder keyed on the
version (~/.cache/mlaunch/pytest-7.4.4), which goes before the venv's site-packages on
PYTHONPATH: the plugins are still found through the venv's entry points. A launch_pytest file
and a launch_testing file collected by pytest must give the results recorded under the
reference. Skipped, saying why, when the package index cannot be reached.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from procutil import clean_env
from test_launch_pytest import EXAMPLES, LAUNCH_TESTING, RECORDED, run_pytest

VERSION = "7.4.4"
CACHE = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "mlaunch"
INDEX = "https://pypi.org/simple/pytest/"
INSTALL_TIMEOUT = 300


def _index_unreachable() -> str | None:
    """Why the package index cannot be reached, or None when it answers."""
    try:
        with urllib.request.urlopen(INDEX, timeout=10):
            return None
    except (urllib.error.URLError, OSError) as e:
        return f"{INDEX} cannot be reached ({e})"


def _install(folder: Path) -> None:
    """pytest VERSION and its dependencies into ``folder``, whole or not at all."""
    partial = folder.with_name(f"{folder.name}.partial-{os.getpid()}")
    shutil.rmtree(partial, ignore_errors=True)
    done = subprocess.run(
        [
            *(sys.executable, "-m", "pip", "install", "--quiet", "--no-input"),
            *("--disable-pip-version-check", "--no-compile", "--target", str(partial)),
            f"pytest=={VERSION}",
        ],
        capture_output=True,
        text=True,
        timeout=INSTALL_TIMEOUT,
        stdin=subprocess.DEVNULL,
    )
    if done.returncode != 0:
        shutil.rmtree(partial, ignore_errors=True)
        unreachable = _index_unreachable()
        if unreachable is not None:
            pytest.skip(f"pytest {VERSION} cannot be installed: {unreachable}")
        pytest.fail(f"pip could not install pytest {VERSION}:\n{done.stdout}{done.stderr}")
    # The executables pip adds would run the venv's python with the wrong path: not needed.
    shutil.rmtree(partial / "bin", ignore_errors=True)
    try:
        partial.rename(folder)
    except OSError:  # another run installed it meanwhile
        shutil.rmtree(partial, ignore_errors=True)


@pytest.fixture(scope="module")
def old_pytest_env() -> dict[str, str]:
    """The environment in which ``python -m pytest`` is pytest VERSION."""
    folder = CACHE / f"pytest-{VERSION}"
    if not (folder / "pytest").is_dir():
        folder.parent.mkdir(parents=True, exist_ok=True)
        # One install at a time: the suite's xdist workers (or another run) that find the
        # folder missing too wait for this one instead of downloading it again.
        lock = os.open(folder.with_name(f"{folder.name}.lock"), os.O_CREAT | os.O_RDWR, 0o666)
        try:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not (folder / "pytest").is_dir():
                _install(folder)
        finally:
            os.close(lock)
    env = clean_env(PYTHONPATH=str(folder))
    shown = subprocess.run(
        [sys.executable, "-m", "pytest", "--version"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
        stdin=subprocess.DEVNULL,
    )
    assert f"pytest {VERSION}" in shown.stdout + shown.stderr, shown.stdout + shown.stderr
    return env


def test_a_launch_pytest_file_under_pytest_74(
    old_pytest_env: dict[str, str], tmp_path: Path
) -> None:
    name = "chatter_fixture.py"
    found, output = run_pytest(EXAMPLES / name, tmp_path, old_pytest_env)
    assert found == RECORDED["ours"][name], output


def test_a_launch_testing_file_collected_by_pytest_74(
    old_pytest_env: dict[str, str], tmp_path: Path
) -> None:
    name = "counting_launch.py"
    shutil.copy(LAUNCH_TESTING / "chatter.py", tmp_path / "chatter.py")
    shutil.copy(LAUNCH_TESTING / "counting.test.py", tmp_path / name)
    found, output = run_pytest(tmp_path / name, tmp_path, old_pytest_env)
    assert found == RECORDED["launch_testing_via_pytest"][name], output
