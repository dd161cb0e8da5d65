"""mlaunch export --to systemd: units that say what the launch says, and that systemd accepts."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from procutil import REPO, clean_env, run_mlaunch

from mlaunch.export.systemd import environment_file, quote_exec

PREFIX = REPO / "launches" / "examples" / "prefix"
LAUNCH = """
from launch import LaunchDescription
from launch.actions import (ExecuteProcess, RegisterEventHandler, SetEnvironmentVariable,
                            TimerAction)
from launch.event_handlers import OnProcessExit, OnProcessStart
from launch_ros.actions import Node

def generate_launch_description():
    setup = ExecuteProcess(cmd=["echo", "setup 100% $HOME"], name="setup")
    server = ExecuteProcess(cmd=["sleep", "1000"], name="server", respawn=True, respawn_delay=2.0,
                            sigterm_timeout=3, sigkill_timeout=4)
    return LaunchDescription([
        SetEnvironmentVariable("MY_VAR", "a b"),
        setup,
        server,
        RegisterEventHandler(OnProcessExit(target_action=setup, on_exit=[
            ExecuteProcess(cmd=["echo", "after setup"], name="after")])),
        RegisterEventHandler(OnProcessStart(target_action=server, on_start=[
            ExecuteProcess(cmd=["sleep", "5"], name="client", required=True)])),
        TimerAction(period=3.0, actions=[ExecuteProcess(cmd=["true"], name="late")]),
        Node(package="mlaunch_demo", executable="talker", parameters=[{"rate": 5}]),
    ])
"""


def export(tmp_path: Path, *extra: str) -> tuple[subprocess.CompletedProcess[str], Path]:
    launch = tmp_path / "demo.launch.py"
    launch.write_text(LAUNCH)
    out = tmp_path / "units"
    env = clean_env(AMENT_PREFIX_PATH=str(PREFIX))
    done = run_mlaunch("export", str(launch), "--to", "systemd", str(out), *extra, env=env)
    return done, out


def unit(out: Path, name: str) -> list[str]:
    return (out / name).read_text().splitlines()


def test_one_service_per_process_with_argv_env_restart_and_stop(tmp_path: Path) -> None:
    done, out = export(tmp_path)
    assert done.returncode == 0, done.stderr
    services = sorted(p.name for p in out.glob("*.service"))
    assert services == [
        "demo-after-5.service",
        "demo-client-6.service",
        "demo-late-4.service",
        "demo-server-2.service",
        "demo-setup-1.service",
        "demo-talker-3.service",
        "demo.service",  # the whole launch under mlaunch (Type=notify)
    ]
    server = unit(out, "demo-server-2.service")
    assert "ExecStart=/usr/bin/sleep 1000" in server or "ExecStart=/bin/sleep 1000" in server
    assert {"Restart=always", "RestartSec=2", "StartLimitIntervalSec=0"} <= set(server)
    assert {"KillMode=control-group", "KillSignal=SIGINT", "TimeoutStopSec=7"} <= set(server)
    environment = next(line for line in server if line.startswith("Environment="))
    assert '"MY_VAR=a b"' in environment.split("=", 1)[1]
    assert f"EnvironmentFile={out}/demo.env" in server
    assert f"WorkingDirectory={os.getcwd()}" in server  # where the export ran, as a launch would
    setup = unit(out, "demo-setup-1.service")
    assert any(line.endswith('echo "setup 100%% $$HOME"') for line in setup), setup
    assert "Restart=no" in setup


def test_launch_ordering_becomes_unit_ordering(tmp_path: Path) -> None:
    done, out = export(tmp_path)
    assert done.returncode == 0, done.stderr
    # OnProcessExit: after the target exited (a oneshot is started once it has exited).
    assert {"Type=oneshot", "RemainAfterExit=yes"} <= set(unit(out, "demo-setup-1.service"))
    after = set(unit(out, "demo-after-5.service"))
    assert {"After=demo-setup-1.service", "Requires=demo-setup-1.service"} <= after
    # OnProcessStart: after the target started; TimerAction: a delay before the start.
    assert "After=demo-server-2.service" in unit(out, "demo-client-6.service")
    assert "ExecStartPre=/bin/sleep 3" in unit(out, "demo-late-4.service")
    target = unit(out, "demo.target")
    assert "BindsTo=demo-client-6.service" in target  # required: its end stops the launch
    assert "WantedBy=multi-user.target" in target


def test_params_files_are_installed_next_to_the_units(tmp_path: Path) -> None:
    done, out = export(tmp_path, "--install-dir", "/opt/robot/units")
    assert done.returncode == 0, done.stderr
    params = out / "params" / "demo-talker-3-0.yaml"
    assert "rate: 5" in params.read_text()
    talker = "\n".join(unit(out, "demo-talker-3.service"))
    assert "--params-file /opt/robot/units/params/demo-talker-3-0.yaml" in talker
    readme = (out / "README.md").read_text()
    assert "systemctl link /opt/robot/units/*.service" in readme
    assert "enable --now demo.target" in readme


@pytest.mark.skipif(
    shutil.which("systemd-analyze") is None,
    reason="systemd-analyze not installed (apt-get install systemd) to verify exported units",
)
def test_systemd_analyze_verify_accepts_the_units(tmp_path: Path) -> None:
    done, out = export(tmp_path, "--user", "root")
    assert done.returncode == 0, done.stderr
    files = [str(p) for p in sorted(out.glob("*.service"))] + [str(out / "demo.target")]
    check = subprocess.run(
        ["systemd-analyze", "verify", *files], capture_output=True, text=True, timeout=60
    )
    assert check.returncode == 0, check.stderr
    assert check.stderr.strip() == "", check.stderr  # not even a warning


def test_bad_requests_are_clear_errors(tmp_path: Path) -> None:
    done, _ = export(tmp_path)
    assert done.returncode == 0
    again, _ = export(tmp_path)
    assert again.returncode == 2 and "is not empty" in again.stderr
    launch = str(tmp_path / "demo.launch.py")
    bad = run_mlaunch("export", launch, "--to", "upstart", str(tmp_path / "x"), env=clean_env())
    assert bad.returncode == 2 and "valid: systemd" in bad.stderr


@pytest.mark.parametrize(
    ("word", "quoted"),
    [
        ("plain", "plain"),
        ("a b", '"a b"'),
        ("100%", "100%%"),
        ("$HOME", "$$HOME"),
        ('say "hi"', '"say \\"hi\\""'),
        ("back\\slash", '"back\\\\slash"'),
        ("", '""'),
        ("two\nlines", '"two\\nlines"'),
        ("cr\rhere", '"cr\\rhere"'),
        ("bell\x07", '"bell\\x07"'),
        (";", '";"'),
    ],
)
def test_exec_words_are_quoted_for_systemd(word: str, quoted: str) -> None:
    assert quote_exec(word) == quoted


def test_the_environment_file_holds_what_was_asked_escaped() -> None:
    text = environment_file({"PATH": "/usr/bin", "ODD": 'a "b" $HOME `x` \\'})
    assert text.splitlines()[1:] == ['ODD="a \\"b\\" \\$HOME \\`x\\` \\\\"', 'PATH="/usr/bin"']


def test_what_systemd_cannot_do_is_a_warning(tmp_path: Path) -> None:
    launch = tmp_path / "lc.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import LifecycleNode\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([LifecycleNode(package='mlaunch_demo', executable='talker',\n"
        "        name='lc', namespace='', autostart=True)])\n"
    )
    out = tmp_path / "units"
    env = clean_env(AMENT_PREFIX_PATH=str(PREFIX))
    done = run_mlaunch("export", str(launch), "--to", "systemd", str(out), env=env)
    assert done.returncode == 0, done.stderr
    assert "lifecycle node with autostart: nothing drives it to active" in done.stderr
    assert "nothing drives it to active" in (out / "README.md").read_text()


def test_the_whole_launch_as_one_notify_service(tmp_path: Path) -> None:
    done, out = export(tmp_path, "extra:=a b")
    assert done.returncode == 0, done.stderr
    service = unit(out, "demo.service")
    assert {"Type=notify", "NotifyAccess=main", "Conflicts=demo.target"} <= set(service)
    # 90 s to be ready, plus the longest timer before a process starts (3 s)
    assert "TimeoutStartSec=93" in service
    assert "KillMode=mixed" in service and "KillSignal=SIGINT" in service
    start = next(line for line in service if line.startswith("ExecStart="))
    assert start.endswith(f'{out}/launch/demo.launch.py "extra:=a b"'), start
    assert (out / "launch" / "demo.launch.py").read_text() == LAUNCH
    assert not (out / "launch" / "units").exists()  # the export is not copied into itself


def test_stand_ins_are_named_and_refused_unless_allowed(tmp_path: Path) -> None:
    launch = tmp_path / "standin.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([Node(package='tf2_ros', executable='static_transform_publisher', arguments=['0','0','0','0','0','0','a','b'])])\n"
    )
    out = tmp_path / "units"
    env = clean_env()
    refused = run_mlaunch("export", str(launch), "--to", "systemd", str(out), env=env)
    assert refused.returncode == 2, refused.stderr
    assert "static_transform_publisher-1: runs mlaunch's stand-in" in refused.stderr, refused.stderr
    assert "tf2_ros/static_transform_publisher is not installed here" in refused.stderr
    assert not out.exists()
    allowed = run_mlaunch(
        "export", str(launch), "--to", "systemd", str(out), "--allow-standins", env=env
    )
    assert allowed.returncode == 0, allowed.stderr
    assert (
        "static_transform_publisher-1: runs mlaunch's stand-in" in (out / "README.md").read_text()
    )
