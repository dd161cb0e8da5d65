"""The differential tests' ``ros2 launch`` runs, forked from a reference interpreter that imported
launch once (tests/reference.py, tests/reference_zygote.py), are what a ``ros2`` process started
cold does: the same exit status, output and environment, a load error the same, a timeout the
same, and no zygote per variable launch reads only when it runs."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import reference

sys.path.insert(0, str(Path(__file__).resolve().parent / "conformance"))
import harness

REFERENCE = harness.reference_environ()
pytestmark = pytest.mark.skipif(REFERENCE is None, reason=reference.MISSING)

LAUNCH = """\
import os
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo
from launch.substitutions import EnvironmentVariable

def generate_launch_description():
    return LaunchDescription([
        LogInfo(msg=["records in ", EnvironmentVariable("CONF_RECORD_DIR")]),
        ExecuteProcess(
            cmd=["/bin/sh", "-c", "echo cwd $PWD; echo log $ROS_LOG_DIR; echo out; echo err >&2;"
                 " exit 3"],
            name="child", output="screen"),
    ])
"""
BROKEN = "def generate_launch_description():\n    raise RuntimeError('no description here')\n"
SLEEPER = """\
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=["sleep", "60"], name="sleeper")])
"""
_PID = re.compile(r"\b(pid \[?|pid )\d+")
_LOG_FOLDER = re.compile(r"All log files can be found below \S+")


def _run(
    tmp_path: Path, name: str, text: str, monkeypatch: pytest.MonkeyPatch, zygote: bool
) -> subprocess.CompletedProcess[str]:
    assert REFERENCE is not None
    work = tmp_path / ("fork" if zygote else "cold") / name
    work.mkdir(parents=True)
    (work / f"{name}.launch.py").write_text(text)
    env = dict(
        REFERENCE,
        HOME=str(Path.home()),
        ROS_LOG_DIR=str(work / "log"),
        CONF_RECORD_DIR=str(work / "records"),
    )
    monkeypatch.setenv("MLAUNCH_REFERENCE_ZYGOTE", "1" if zygote else "0")
    ros2 = str(Path(REFERENCE["PATH"].split(":")[0]) / "ros2")
    return reference.run_ros2([ros2, "launch", f"{name}.launch.py"], env=env, cwd=work, timeout=60)


def _same(text: str, work: Path) -> list[str]:
    """The lines with what differs from run to run named: the run's folder, pids, log folder."""
    text = _LOG_FOLDER.sub(
        "All log files can be found below <log>", text.replace(str(work), "<work>")
    )
    return sorted(_PID.sub(r"\1<pid>", text).splitlines())


@pytest.mark.parametrize("name, text", [("child", LAUNCH), ("broken", BROKEN)])
def test_a_forked_run_is_a_cold_run(
    name: str, text: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cold = _run(tmp_path, name, text, monkeypatch, zygote=False)
    fork = _run(tmp_path, name, text, monkeypatch, zygote=True)
    assert fork.returncode == cold.returncode
    assert _same(fork.stdout, tmp_path / "fork" / name) == _same(
        cold.stdout, tmp_path / "cold" / name
    )
    assert _same(fork.stderr, tmp_path / "fork" / name) == _same(
        cold.stderr, tmp_path / "cold" / name
    )
    if name == "child":  # what the run was given, not what the zygote was started with
        assert cold.returncode == 0, cold.stdout + cold.stderr
        out = fork.stdout + fork.stderr
        assert f"records in {tmp_path / 'fork' / name / 'records'}" in out, out
        assert f"[child-1] cwd {tmp_path / 'fork' / name}" in out, out
        assert f"[child-1] log {tmp_path / 'fork' / name / 'log'}" in out, out
        assert "[child-1] err" in out and "exit code 3" in out, out
    else:
        assert cold.returncode == 1 and "no description here" in fork.stdout + fork.stderr


def test_one_zygote_serves_runs_that_differ_only_in_what_launch_reads_late(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _run(tmp_path / "one", "child", LAUNCH, monkeypatch, zygote=True)
    servers = {key: zygote.pid for key, zygote in reference._zygotes.items()}
    _run(tmp_path / "two", "child", LAUNCH, monkeypatch, zygote=True)  # other folders
    assert {key: zygote.pid for key, zygote in reference._zygotes.items()} == servers


def test_a_run_past_its_timeout_is_killed_with_its_children(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert REFERENCE is not None
    monkeypatch.delenv("MLAUNCH_REFERENCE_ZYGOTE", raising=False)
    work = tmp_path / "sleeper"
    work.mkdir()
    (work / "sleeper.launch.py").write_text(SLEEPER)
    env = dict(REFERENCE, HOME=str(Path.home()), ROS_LOG_DIR=str(work / "log"))
    ros2 = str(Path(REFERENCE["PATH"].split(":")[0]) / "ros2")
    with pytest.raises(subprocess.TimeoutExpired):
        reference.run_ros2([ros2, "launch", "sleeper.launch.py"], env=env, cwd=work, timeout=3)
    sleepers = subprocess.run(["pgrep", "-f", "^sleep 60$"], capture_output=True, text=True)
    for pid in sleepers.stdout.split():
        assert not Path(f"/proc/{pid}/cwd").resolve().is_relative_to(work), pid
