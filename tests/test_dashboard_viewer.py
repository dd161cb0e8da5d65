"""The launch panel on the viewer's page: the jtbot's run seen and steered from the address the
viewer prints, in headless Chromium (issue 36)."""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any

import pytest
from browser import Browser, available
from conftest import requires_rclpy
from procutil import REPO, Running, mlaunch, run_mlaunch
from test_dashboard import assert_refuses_strangers

OPEN = r"viewer: open http://127\.0\.0\.1:(\d+)/"
JTBOT = ("gazebo-1", "robot_state_publisher-2", "spawn_entity.py-3", "rviz2-4")
# The panel is the viewer page's iframe, of the same origin: its document is reachable.
PANEL = "document.getElementById('launch').contentDocument"


def row(label: str, field: str) -> str:
    """Script reading one data field of ``label``'s row in the panel."""
    return f"{PANEL}.querySelector('tr[data-label=\"{label}\"]').dataset.{field}"


@requires_rclpy
@pytest.mark.timeout(150)
@pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")
def test_the_viewer_page_shows_the_jtbot_run_and_restarts_a_node(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    env = {**ros_env, "ROS_LOG_DIR": str(tmp_path / "logs"), "NO_COLOR": "1"}
    env.pop("MLAUNCH_VIEWER_PORT", None)
    launch = str(REPO / "launches" / "jtbot_sim.launch.py")
    run = Running(mlaunch(launch), env=env, cwd=str(tmp_path))
    try:
        port = int(run.wait_for(OPEN, 60).group(1))
        with Browser(tmp_path / "profile", width=1600, height=900) as browser:
            page = browser.open(f"http://127.0.0.1:{port}/")
            page.wait("document.body.classList.contains('with-panel')", 30, "the launch panel")
            # every jtbot process, the simulator with live CPU
            page.wait(
                f"{PANEL}.body.dataset.updates > 1 && Number({row('gazebo-1', 'cpu')}) > 0",
                60,
                "the simulator's CPU in the panel",
            )
            labels = page.eval(
                f"[...{PANEL}.querySelectorAll('#procs tbody tr')].map(r => r.dataset.label)"
            )
            assert tuple(labels) == JTBOT
            before = int(page.eval(row("robot_state_publisher-2", "pid")))
            frame = "document.getElementById('launch').contentWindow"
            clicked = page.eval(
                f"(() => {{ const b = {PANEL}.querySelector("
                '\'tr[data-label="robot_state_publisher-2"] button[data-op="restart"]\');'
                " b.click(); return true; })()"
            )
            assert clicked
            answer = json.loads(
                page.wait(f"{frame}.document.body.dataset.lastControl", 60, "the restart")
            )
            assert answer["ok"] and answer["pid"] not in (0, before), answer
            done = run_mlaunch("ctl", "list", "--json", env=env, timeout=30)
            listed: dict[str, Any] = {p["label"]: p for p in json.loads(done.stdout)["processes"]}
            assert listed["robot_state_publisher-2"]["pid"] == answer["pid"]
            assert listed["robot_state_publisher-2"]["restarts"] == 1
            page.wait(
                f"{row('robot_state_publisher-2', 'pid')} == {answer['pid']}", 15, "the new pid"
            )
        # through the viewer's address, the same refusals as the panel's own port
        assert_refuses_strangers(port, "robot_state_publisher-2")
        run.signal(signal.SIGINT)
        assert run.finish(60) == 130
    finally:
        if run.proc.poll() is None:
            run.kill()
