"""The smartcar seed natively on Debian's ROS 1 with every program real, driven as the seed's
own test drives it: ``mlaunch launches/smartcar_display.launch`` in a ROS 1 shell (the packages
``scripts/setup --ros1-sources`` makes, sourced from .venv/ros1/setup.sh) runs arbotix_driver
(simulated), joint_state_publisher, robot_state_publisher, tf's two static_transform_publishers
and RViz (under Xvfb), and ``rostopic pub -r 10 /cmd_vel ...`` moves the car: /odom changes and
TF's odom -> base_link follows it."""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import xmlrpc.client
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from ports import free_port
from procutil import Running, wait_for
from ros1tree import SYSTEM_PYTHON, requires_roslaunch

REPO = Path(__file__).resolve().parent.parent
SETUP = REPO / ".venv" / "ros1" / "setup.sh"
PROBE = Path(__file__).resolve().parent / "ros1_odom_probe.py"
PROGRAMS = (
    "/usr/lib/tf/static_transform_publisher",
    "/usr/lib/rviz/rviz",
    "/usr/lib/robot_state_publisher/robot_state_publisher",
    "/usr/bin/rostopic",
)
# The seed's own line (001_667a322066b91c00.txt), word for word.
TWIST = "{linear: {x: 0.5, y: 0, z: 0}, angular: {x: 0, y: 0, z: 0.5}}"
NODES = {
    "/arbotix",
    "/joint_state_publisher",
    "/robot_state_publisher",
    "/odom_left_wheel_broadcaster",
    "/odom_right_wheel_broadcaster",
    "/rviz",
    "/rosout",
}

pytestmark = [
    requires_roslaunch,
    pytest.mark.skipif(
        not SETUP.is_file(),
        reason="arbotix_python is not made: run scripts/setup --ros1-sources DIR"
        " (CI always does, from ../shared/ros1-src)",
    ),
    pytest.mark.skipif(
        shutil.which("Xvfb") is None or not all(os.access(p, os.X_OK) for p in PROGRAMS),
        reason="Xvfb, tf-tools, rviz, robot_state_publisher or rostopic is not installed",
    ),
    pytest.mark.timeout(240),
]


def ros1_shell(tmp_path: Path, port: int) -> dict[str, str]:
    """The environment a shell has after sourcing .venv/ros1/setup.sh (a ROS 1 shell)."""
    base = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CMAKE_"))}
    base.pop("PYTHONPATH", None)
    base.update(ROS_MASTER_URI=f"http://localhost:{port}/", HOME=str(tmp_path))
    done = subprocess.run(
        ["bash", "-c", f". {SETUP} && env -0"], env=base, capture_output=True, check=True
    )
    env = dict(e.split("=", 1) for e in done.stdout.decode().split("\0") if "=" in e)
    env.update(ROS_HOME=str(tmp_path / "ros"), PYTHONUNBUFFERED="1")
    return env


@pytest.fixture
def display(tmp_path: Path) -> Iterator[str]:
    """A private X server (Xvfb picks a free display and says which)."""
    read, write = os.pipe()
    xvfb = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1280x900x24", "-nolisten", "tcp"],
        pass_fds=(write,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    os.close(write)
    with os.fdopen(read) as f:
        number = f.readline().strip()
    try:
        assert number.isdigit(), "Xvfb did not say its display"
        yield f":{number}"
    finally:
        xvfb.terminate()
        xvfb.wait(timeout=20)


def registered(port: int) -> set[str]:
    master: Any = xmlrpc.client.ServerProxy(f"http://localhost:{port}/")
    try:
        state: list[list[tuple[str, list[str]]]] = master.getSystemState("/t")[2]
    except OSError:
        return set()
    return {node for group in state for _, nodes in group for node in nodes}


class Probe:
    """tests/ros1_odom_probe.py under Debian's Python: the odometry and TF, line by line."""

    def __init__(self, env: dict[str, str]) -> None:
        self.proc = subprocess.Popen(
            [SYSTEM_PYTHON, str(PROBE)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env=env,
            text=True,
        )
        self.samples: list[dict[str, Any]] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.samples.append(json.loads(line))

    def latest(self) -> dict[str, Any] | None:
        return self.samples[-1] if self.samples else None

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


def test_the_seed_runs_every_program_for_real_and_drives(tmp_path: Path, display: str) -> None:
    port = free_port()
    env = ros1_shell(tmp_path, port)
    env["DISPLAY"] = display
    launch = REPO / "launches" / "smartcar_display.launch"
    run = Running([sys.executable, "-m", "mlaunch", str(launch)], env=env)
    probe: Probe | None = None
    pub: subprocess.Popen[bytes] | None = None
    try:
        wait_for(
            lambda: registered(port) >= NODES,
            timeout=90,
            what=f"every node of the seed registered: {run.text[-3000:]}",
        )
        assert "cannot launch" not in run.text, run.text
        probe = Probe(env)
        first = wait_for(probe.latest, timeout=60, what="an /odom message")
        assert math.hypot(*first["odom"][:2]) < 1e-6, first  # at rest where it started
        pub = subprocess.Popen(
            ["/usr/bin/rostopic", "pub", "-r", "10", "/cmd_vel", "geometry_msgs/Twist", TWIST],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )

        def moved() -> dict[str, Any] | None:
            last = probe.latest() if probe else None
            return last if last and math.hypot(*last["odom"][:2]) > 0.3 else None

        driven = wait_for(moved, timeout=60, what=f"the car moving: {probe.samples[-3:]}")
        # TF's odom -> base_link at the odometry's stamp is the odometry's pose
        assert driven["tf"] is not None, driven
        for ours, theirs in zip(driven["odom"], driven["tf"], strict=True):
            assert abs(ours - theirs) < 1e-3, driven
        # turning left at 0.5 rad/s while going forward: y grows, the heading turns left
        assert driven["odom"][1] > 0 or driven["odom"][2] != 0, driven
    finally:
        if pub is not None:
            pub.terminate()
            pub.wait(timeout=20)
        if probe is not None:
            probe.close()
        run.signal(signal.SIGINT)
        code = run.finish(timeout=60)
    assert code == 0 or code == 130, run.text[-3000:]
    assert not registered(port)  # the master mlaunch started ended with the run


def test_mlaunch_test_checks_the_seed_s_topics(tmp_path: Path, display: str) -> None:
    """``mlaunch test`` on the seed, natively: every node registered, /odom and /tf read
    through the rospy helper (arbotix publishes /odom at its controller's 10 Hz; half of it
    is asked, for a loaded machine)."""
    port = free_port()
    env = ros1_shell(tmp_path, port)
    env["DISPLAY"] = display
    launch = REPO / "launches" / "smartcar_display.launch"
    argv = [sys.executable, "-m", "mlaunch", "test", str(launch), "--timeout", "90"]
    argv += ["--expect-topic", "/odom:5", "--expect-topic", "/tf", "--hold", "1"]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=200, check=False)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    rows = done.stdout.splitlines()
    odom = next(x for x in rows if "topic /odom " in x)
    assert re.search(r"\d+\.\d Hz over", odom), odom
    assert any("topic /tf " in x and "received" in x for x in rows), rows
    for node in NODES:
        assert any(f"node {node} " in x and "in the graph" in x for x in rows), node
    assert not registered(port)
