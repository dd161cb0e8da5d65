"""scripts/ros1_sources/build.py: the ROS 1 packages Debian lacks (arbotix_python, its
messages), made from pinned source archives into a cached catkin install space that Debian's
Python imports and roslaunch's lookup finds."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from ros1tree import SYSTEM_PYTHON, requires_roslaunch

REPO = Path(__file__).resolve().parent.parent
BUILD = REPO / "scripts" / "ros1_sources" / "build.py"
SOURCES = REPO.parent / "shared" / "ros1-src"  # CI's folder of source archives

pytestmark = [
    requires_roslaunch,
    pytest.mark.skipif(
        not (SOURCES / "MANIFEST.tsv").is_file(),
        reason="no ../shared/ros1-src beside the clone (CI's ROS 1 source archives)",
    ),
]


def build(*args: str, cache: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "MLAUNCH_ROS1_CACHE": str(cache)}
    argv = [sys.executable, str(BUILD), *args]
    return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=300, check=False)


def missing() -> str:
    done = build(str(SOURCES), "--missing", cache=Path("/nonexistent"))
    return done.stdout.strip()


def test_archives_that_are_not_the_pinned_ones_are_refused(tmp_path: Path) -> None:
    sources = tmp_path / "src"
    sources.mkdir()
    manifest = (SOURCES / "MANIFEST.tsv").read_text()
    (sources / "MANIFEST.tsv").write_text(manifest)
    (sources / "arbotix_ros.tar.gz").write_bytes(b"not the archive")
    done = build(str(sources), cache=tmp_path / "cache")
    assert done.returncode == 2, done.stderr
    assert "arbotix_ros.tar.gz has sha256" in done.stderr and "not the pinned" in done.stderr
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").iterdir())
    (sources / "MANIFEST.tsv").write_text(manifest.splitlines()[0] + "\n")
    done = build(str(sources), cache=tmp_path / "cache")
    assert done.returncode == 2 and "lacks arbotix_ros.tar.gz" in done.stderr, done.stderr


@pytest.mark.skipif(bool(missing()), reason=f"Debian packages missing: {missing()}")
def test_arbotix_is_built_once_and_found_as_roslaunch_finds_it(tmp_path: Path) -> None:
    before = build(str(SOURCES), "--cached", cache=tmp_path / "cache")
    assert before.returncode == 3 and not before.stdout  # not built yet: setup checks and builds
    done = build(str(SOURCES), cache=tmp_path / "cache")
    assert done.returncode == 0, done.stderr
    prefix = Path(done.stdout.strip())
    assert prefix.parent == tmp_path / "cache"
    complete = (prefix / ".complete").stat().st_mtime_ns
    again = build(str(SOURCES), cache=tmp_path / "cache")
    assert again.stdout == done.stdout  # cached: the same prefix, not built again
    assert (prefix / ".complete").stat().st_mtime_ns == complete
    assert build(str(SOURCES), "--cached", cache=tmp_path / "cache").stdout == done.stdout
    # A shell that sources its setup.sh: roslib finds the driver, Debian's Python imports it
    probe = (
        "import roslib.packages, rospkg; import arbotix_msgs.srv, control_msgs.msg;"
        " from arbotix_python.diff_controller import DiffController;"
        " print(roslib.packages.find_node('arbotix_python', 'arbotix_driver')[0])"
    )
    script = f'. {prefix}/setup.sh && echo $ROS_VERSION && {SYSTEM_PYTHON} -c "{probe}"'
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CMAKE_", "PYTHON"))}
    shell = subprocess.run(
        ["bash", "-c", script], env=env, capture_output=True, text=True, check=False
    )
    assert shell.returncode == 0, shell.stderr
    assert shell.stdout.split() == ["1", str(prefix / "lib" / "arbotix_python" / "arbotix_driver")]
    shutil.rmtree(tmp_path / "cache")
