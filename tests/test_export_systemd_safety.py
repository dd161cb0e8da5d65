"""mlaunch export --to systemd against hostile values: nothing injects a directive or a specifier,
and the caller's environment stays home (issue 27, items 6 and 7)."""

from __future__ import annotations

import shutil
import stat
import subprocess
from pathlib import Path

import pytest
from procutil import REPO, clean_env, mlaunch, run_mlaunch

PREFIX = REPO / "launches" / "examples" / "prefix"
LAUNCH = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("name", default_value="worker"),
        DeclareLaunchArgument("cwd", default_value="/"),
        ExecuteProcess(cmd=["sleep", "1000"], name=LaunchConfiguration("name"),
                       cwd=LaunchConfiguration("cwd")),
        Node(package="mlaunch_demo", executable="talker", parameters=[{"rate": 5}]),
    ])
"""
# Every key a unit mlaunch writes may hold: anything else is a directive someone injected.
KEYS = {
    "Description", "PartOf", "After", "Requires", "StartLimitIntervalSec", "Type",
    "RemainAfterExit", "User", "ExecStart", "WorkingDirectory", "EnvironmentFile", "Environment",
    "UnsetEnvironment", "Restart", "RestartSec", "KillMode", "KillSignal", "TimeoutStopSec",
    "TimeoutStartSec", "NotifyAccess", "WatchdogSec", "Conflicts",
    "SyslogIdentifier", "Wants", "BindsTo", "WantedBy",
}  # fmt: skip
verify_needed = pytest.mark.skipif(
    shutil.which("systemd-analyze") is None,
    reason="systemd-analyze not installed (apt-get install systemd) to verify exported units",
)


def export(
    tmp_path: Path, *extra: str, env: dict[str, str] | None = None
) -> tuple[subprocess.CompletedProcess[str], Path]:
    launch = tmp_path / "demo.launch.py"
    launch.write_text(LAUNCH)
    out = tmp_path / "units"
    env = env or clean_env(AMENT_PREFIX_PATH=str(PREFIX))
    done = run_mlaunch("export", str(launch), "--to", "systemd", str(out), *extra, env=env)
    return done, out


def keys(path: Path) -> list[str]:
    lines = [line for line in path.read_text().splitlines() if line and not line.startswith("[")]
    return [line.split("=", 1)[0] for line in lines]


def verify(out: Path) -> subprocess.CompletedProcess[str]:
    files = [str(p) for p in sorted(out.glob("*.service"))] + sorted(
        str(p) for p in out.glob("*.target")
    )
    return subprocess.run(
        ["systemd-analyze", "verify", *files], capture_output=True, text=True, timeout=60
    )


@pytest.mark.parametrize(
    ("extra", "named"),
    [
        (["name:=x\nExecStartPre=/bin/touch /tmp/pwned"], "process name"),
        (["name:=x\rExecStartPre=/bin/touch /tmp/pwned"], "process name"),
        (["--user", "root\nExecStartPre=/bin/touch /tmp/pwned"], "--user"),
        (["--install-dir", "/opt/a\nExecStartPre=/bin/touch /tmp/pwned"], "environment file"),
        (["--env", "TOKEN=a\nb"], "environment variable TOKEN"),
        (["--env", "BAD-NAME=1"], "environment variable name"),
        (["--env", "NOT_SET_ANYWHERE_27"], "no such variable"),
    ],
)
def test_a_value_a_unit_cannot_hold_is_refused_by_name(
    tmp_path: Path, extra: list[str], named: str
) -> None:
    done, out = export(tmp_path, *extra)
    assert done.returncode == 2, done.stderr
    assert named in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert not out.exists()  # nothing half-written


@pytest.mark.parametrize(
    ("folder", "why"),
    [("odd\nExecStartPre=x", "a newline"), ("ends\\", "ends with a backslash")],
)
def test_a_working_directory_a_unit_cannot_hold_is_refused(
    tmp_path: Path, folder: str, why: str
) -> None:
    odd = tmp_path / folder
    odd.mkdir()
    done, out = export(tmp_path, f"cwd:={odd}")
    assert done.returncode == 2, done.stderr
    assert "working directory" in done.stderr and why in done.stderr
    assert not out.exists()


@verify_needed
@pytest.mark.parametrize("user", [[], ["--user", "root"]])
def test_percent_signs_are_escaped_everywhere_and_systemd_loads_the_units(
    tmp_path: Path, user: list[str]
) -> None:
    cwd = tmp_path / "100%h %Z"
    cwd.mkdir()
    install = tmp_path / "inst%Z"
    done, out = export(
        tmp_path, "name:=w%Z", f"cwd:={cwd}", "--install-dir", str(install), "--name", "r%Z", *user
    )
    assert done.returncode == 0, done.stderr
    worker = out / "r_Z-w_Z-1.service"
    text = worker.read_text().splitlines()
    assert f"WorkingDirectory={tmp_path}/100%%h %%Z" in text
    assert f"EnvironmentFile={tmp_path}/inst%%Z/r_Z.env" in text
    assert "SyslogIdentifier=w%%Z-1" in text
    assert "Description=w%%Z-1 of demo.launch.py (mlaunch export)" in text
    for unit in [*out.glob("*.service"), *out.glob("*.target")]:
        assert set(keys(unit)) <= KEYS, unit.read_text()
    check = verify(out)
    assert check.returncode == 0, check.stderr
    assert check.stderr.strip() == "", check.stderr


@verify_needed
def test_the_injection_that_systemd_would_have_accepted(tmp_path: Path) -> None:
    # What the refusal prevents: the same unit with the newline left in loads without a word.
    done, out = export(tmp_path, "name:=plain")
    assert done.returncode == 0, done.stderr
    unit = out / "demo-plain-1.service"
    injected = unit.read_text().replace(
        "SyslogIdentifier=plain-1", "SyslogIdentifier=plain-1\nExecStartPre=/bin/true"
    )
    unit.write_text(injected)
    assert verify(out).returncode == 0
    assert "ExecStartPre" in keys(unit)


def test_the_environment_file_holds_only_what_the_user_asked_for_and_is_private(
    tmp_path: Path,
) -> None:
    env = clean_env(
        AMENT_PREFIX_PATH=str(PREFIX), AWS_SECRET_ACCESS_KEY="hunter2", ROS_DOMAIN_ID="27"
    )
    done, out = export(
        tmp_path, "--env", "ROS_*", "--env", "AMENT_PREFIX_PATH", "--env", "EXTRA=a $b", env=env
    )
    assert done.returncode == 0, done.stderr
    text = (out / "demo.env").read_text()
    assert "hunter2" not in text and "AWS_SECRET" not in text
    assert 'ROS_DOMAIN_ID="27"' in text and f'AMENT_PREFIX_PATH="{PREFIX}"' in text
    assert 'EXTRA="a \\$b"' in text
    assert "PATH=" not in text.replace("AMENT_PREFIX_PATH", "")
    for private in [out / "demo.env", *(out / "params").iterdir()]:
        assert stat.S_IMODE(private.stat().st_mode) == 0o600, private
    assert stat.S_IMODE((out / "params").stat().st_mode) == 0o700


def test_without_env_the_file_is_empty_and_the_nodes_are_warned_about(tmp_path: Path) -> None:
    env = clean_env(AMENT_PREFIX_PATH=str(PREFIX), AWS_SECRET_ACCESS_KEY="hunter2")
    done, out = export(tmp_path, env=env)
    assert done.returncode == 0, done.stderr
    lines = (out / "demo.env").read_text().splitlines()
    assert [line for line in lines if not line.startswith("#")] == []
    assert "demo.env is empty: the nodes get systemd's environment" in done.stderr


# --- issue 38, item 16: what systemd reads differently from what was meant -------------------

TIMES = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess, TimerAction

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=["sleep", "1000"], name="long", sigterm_timeout="1000000",
                       sigkill_timeout="5", respawn=True, respawn_delay=2000000.0),
        ExecuteProcess(cmd=["sleep", "1000"], name="short", sigterm_timeout="-7",
                       sigkill_timeout="-1", respawn=True, respawn_delay=0.0),
        ExecuteProcess(cmd=["sleep", "1000"], name="endless", sigterm_timeout="1e300"),
        TimerAction(period=1e6, actions=[ExecuteProcess(cmd=["sleep", "1000"], name="late")]),
    ])
"""


@verify_needed
def test_huge_and_negative_times_are_written_as_systemd_reads_them(tmp_path: Path) -> None:
    launch = tmp_path / "times.launch.py"
    launch.write_text(TIMES)
    out = tmp_path / "units"
    done = run_mlaunch("export", str(launch), "--to", "systemd", str(out), env=clean_env())
    assert done.returncode == 0, done.stderr
    long, short, endless, late = (
        (out / f"times-{name}.service").read_text().splitlines()
        for name in ("long-1", "short-2", "endless-3", "late-4")
    )
    # before: 1e+06 and -8, which systemd ignores (its defaults apply: 90 s, 100 ms)
    assert "TimeoutStopSec=1000005" in long and "RestartSec=2000000" in long
    assert "TimeoutStopSec=0.000001" in short and "RestartSec=0" in short  # 0 would be "never"
    assert "TimeoutStopSec=infinity" in endless
    assert "ExecStartPre=/bin/sleep 1000000" in late and "TimeoutStartSec=1000090" in late
    check = verify(out)
    assert check.returncode == 0, check.stderr
    assert check.stderr.strip() == "", check.stderr


@pytest.mark.parametrize("first", ["-", "@", "+", "!", ":"])
def test_a_program_found_through_a_relative_path_entry_is_written_absolute(
    tmp_path: Path, first: str
) -> None:
    # `ExecStart=-x` runs `x` with its failure ignored; `@x` runs x named otherwise, `+x` with
    # full privileges: a program whose name starts so must never be written relative.
    work = tmp_path / "work"
    work.mkdir()
    program = work / f"{first}prog"
    program.write_text("#!/bin/sh\nexit 0\n")
    program.chmod(0o755)
    launch = tmp_path / "rel.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "def generate_launch_description():\n"
        f"    return LaunchDescription([ExecuteProcess(cmd=[{program.name!r}], name='p')])\n"
    )
    out = tmp_path / "units"
    env = clean_env(PATH=":" + clean_env()["PATH"])  # an empty entry: the current folder
    done = subprocess.run(
        mlaunch("export", str(launch), "--to", "systemd", str(out)),
        capture_output=True, text=True, env=env, cwd=work, timeout=60,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    (start,) = [
        line
        for line in (out / "rel-p-1.service").read_text().splitlines()
        if line.startswith("ExecStart=")
    ]
    assert start == f"ExecStart={program}", start
