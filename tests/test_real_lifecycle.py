"""mlaunch on ros2/demos' C++ lifecycle package (lifecycle_talker, lifecycle_listener,
lifecycle_service_client), where ``scripts/setup --real-nodes`` built it (CI does).

No stand-in exists for these programs: without the build, the launch files here name a package
that is not installed, so the tests skip, saying so.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest
from conftest import VENV_PREFIX, requires_rclpy
from procutil import mlaunch
from test_real_nodes import env_for

HERE = Path(__file__).resolve().parent / "real_nodes"
PREFIX = Path(VENV_PREFIX)
TALKER = PREFIX / "lib" / "lifecycle" / "lifecycle_talker"
DEMO = PREFIX / "share" / "lifecycle" / "launch" / "lifecycle_demo_launch.py"
requires_lifecycle = pytest.mark.skipif(
    not os.access(TALKER, os.X_OK),
    reason=f"the real C++ lifecycle demo is not built ({TALKER} is missing): run scripts/setup"
    " --real-nodes [DIR] (CI always builds it)",
)
pytestmark = [requires_rclpy, requires_lifecycle, pytest.mark.timeout(150)]


# What each test expects of the listener: the talker's messages, sent only while it is active.
HEARS_DATA = ("--expect-output", r"lifecycle_listener:data_callback: Lifecycle HelloWorld #\d+")


def passes_test(env: dict[str, str], cwd: Path, *argv: str) -> str:
    """`mlaunch test ARGV` on the real programs (none replaced by a stand-in) passes: its output."""
    done = subprocess.run(
        mlaunch("test", *argv, "--expect-lifecycle", "/lc_talker", *HEARS_DATA,
                "--timeout", "90", "--hold", "1"),
        capture_output=True, text=True, env=env, timeout=140, cwd=cwd,
    )  # fmt: skip
    out = done.stdout + done.stderr
    assert done.returncode == 0, out[-4000:]
    assert "not installed" not in out, out[-4000:]
    return out


def test_the_real_lifecycle_talker_autostarts_and_the_listener_hears_it(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """The C++ talker under a LifecycleNode with autostart: mlaunch configures and activates it
    (its own callbacks say so), --expect-lifecycle sees it active, and the real listener
    receives what its lifecycle publisher sends only once active."""
    launch = HERE / "lifecycle_autostart.launch.py"
    env = env_for(ros_env, tmp_path, real=True)
    shown = subprocess.run(
        mlaunch(str(launch), "--print"), capture_output=True, text=True, env=env, timeout=60
    )
    assert shown.returncode == 0, shown.stderr
    assert str(TALKER) in shown.stdout, shown.stdout
    assert str(TALKER.with_name("lifecycle_listener")) in shown.stdout, shown.stdout
    out = passes_test(env, tmp_path, str(launch))
    assert "[lc_talker]: on_configure() is called." in out, out[-4000:]
    assert "[lc_talker]: on_activate() is called." in out, out[-4000:]
    assert "lifecycle node /lc_talker is active" in out, out[-4000:]
    assert "[lc_talker]: Lifecycle publisher is active. Publishing: [Lifecycle HelloWorld #" in out


def test_the_upstream_lifecycle_demo_launch_file(ros_env: dict[str, str], tmp_path: Path) -> None:
    """The package's own lifecycle_demo_launch.py, by package and file name: its service client
    drives the talker through its transitions (one each 10 s), which the listener is notified
    of, and the talker publishes to it while active."""
    assert DEMO.is_file(), f"the build installs the demo's launch file as {DEMO}"
    passes_test(
        env_for(ros_env, tmp_path, real=True), tmp_path, "lifecycle", "lifecycle_demo_launch.py",
        "--expect-output", r"lifecycle_listener:notify callback: Transition from state \w+ to \w+",
        # The client's calls, answered by the talker: configure (1), then activate (3).
        "--expect-output", "lifecycle_service_client:Transition 1 successfully triggered",
        "--expect-output", "lifecycle_service_client:Transition 3 successfully triggered",
    )  # fmt: skip
