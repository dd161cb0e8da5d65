"""``mlaunch test --junit PATH`` writes into what PATH is: a FIFO or a device stays what it is
(a temporary file renamed over ``/dev/null`` replaced the system's ``/dev/null`` as root), a
regular file is replaced atomically, and a path that cannot be written is found before the run.
"""

from __future__ import annotations

import os
import stat
import threading
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

LAUNCH = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(name='hello', output='screen',
        cmd=[sys.executable, '-c', 'import time; print("ready", flush=True); time.sleep(60)'])])
"""


def _launch(tmp_path: Path) -> str:
    path = tmp_path / "hello.launch.py"
    path.write_text(LAUNCH)
    return str(path)


def _test(tmp_path: Path, report: str) -> tuple[int, str]:
    done = run_mlaunch(
        "test", _launch(tmp_path), "--expect-output", "ready", "--hold", "0", "--junit", report,
        env=clean_env(ROS_LOG_DIR=str(tmp_path / "log")),
    )  # fmt: skip
    return done.returncode, done.stdout + done.stderr


def test_a_fifo_stays_a_fifo_and_gets_the_report(tmp_path: Path) -> None:
    fifo = tmp_path / "report.fifo"
    os.mkfifo(fifo)
    got: list[bytes] = []

    def read() -> None:
        with open(fifo, "rb") as f:  # blocks until mlaunch opens it to write
            got.append(f.read())

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    code, out = _test(tmp_path, str(fifo))
    assert code == 0, out
    reader.join(timeout=30)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)  # not renamed over
    suite = ET.fromstring(got[0]).find("testsuite")
    assert suite is not None and suite.get("failures") == "0"


@pytest.mark.skipif(os.geteuid() != 0, reason="making a device node (mknod) needs root")
def test_a_device_stays_a_device(tmp_path: Path) -> None:
    null = tmp_path / "null"
    os.mknod(null, stat.S_IFCHR | 0o666, os.makedev(1, 3))  # the same device as /dev/null
    code, out = _test(tmp_path, str(null))
    assert code == 0, out
    st = os.lstat(null)
    assert stat.S_ISCHR(st.st_mode) and st.st_rdev == os.makedev(1, 3)


def test_a_regular_file_is_replaced_and_keeps_its_mode(tmp_path: Path) -> None:
    report = tmp_path / "report.xml"
    report.write_text("old")
    report.chmod(0o640)
    link = tmp_path / "link.xml"
    link.symlink_to(report.name)
    code, out = _test(tmp_path, str(link))
    assert code == 0, out
    assert link.is_symlink()  # the report behind it was replaced, not the link
    assert ET.parse(report).getroot().tag == "testsuites"
    assert stat.S_IMODE(report.stat().st_mode) == 0o640
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")] == []


@pytest.mark.parametrize("where", ["under-a-file", "a-folder"])
def test_a_report_that_cannot_be_written_is_refused_before_the_run(
    tmp_path: Path, where: str
) -> None:
    """It was found after the whole test: "PASSED", then an internal error, exit 70."""
    blocker = tmp_path / "blocker"
    if where == "under-a-file":
        blocker.write_text("a file, not a folder")
        report = blocker / "report.xml"
        said = f"--junit {report}: the report could not be written there: Not a directory"
    else:
        blocker.mkdir()
        report = blocker
        said = f"--junit {report}: that is a folder; name a file in it"
    code, out = _test(tmp_path, str(report))
    assert code == 2, out
    assert said in out
    assert "ready" not in out and "PASSED" not in out  # nothing was started
