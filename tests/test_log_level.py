"""``--log-level [NAME:=]LEVEL``: one log level for every ROS process of a launch (composable
nodes through their container's command line, since rclcpp_components reads no log level from
a load request) and for mlaunch's own lines."""

from __future__ import annotations

from pathlib import Path

import pytest
from procutil import REPO, clean_env, run_mlaunch

from mlaunch.app.options import log_level, own_log_level
from mlaunch.engine.output import Printer
from mlaunch.plan.errors import UsageError


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))


def _argvs(text: str) -> dict[str, str]:
    """label -> argv line of a --print."""
    found: dict[str, str] = {}
    label = ""
    for line in text.splitlines():
        if line and not line.startswith((" ", "warning", "Plan", "component /", "log", "handler")):
            label = line.split()[0]
        elif line.startswith("  argv:") and label:
            found[label] = line
    return found


def test_every_ros_process_gets_the_level_a_container_included(env: dict[str, str]) -> None:
    composed = REPO / "launches" / "jtbot_composed.launch.py"
    done = run_mlaunch(str(composed), "--print", "--log-level", "WARN", "--log-level",
                       "robot_state_publisher:=debug", env=env)  # fmt: skip
    assert done.returncode == 0, done.stderr
    argvs = _argvs(done.stdout)
    assert {"component_container-1", "joint_state_publisher-2", "rviz2-3"} <= set(argvs)
    for label, argv in argvs.items():
        assert argv.endswith("--log-level warn --log-level robot_state_publisher:=debug"), label


def test_a_plain_process_is_no_ros_node_and_gets_none(tmp_path: Path, env: dict[str, str]) -> None:
    path = tmp_path / "plain.launch.xml"
    path.write_text('<launch><executable cmd="echo hi" name="plain"/></launch>\n')
    done = run_mlaunch(str(path), "--print", "--log-level", "debug", env=env)
    assert done.returncode == 0, done.stderr
    assert _argvs(done.stdout) == {"plain-1": "  argv:    echo hi"}


@pytest.mark.parametrize(
    ("given", "taken"),
    [
        ("INFO", "info"),
        ("warning", "warn"),
        ("nav2:=Error", "nav2:=error"),
        ("a.b:=fatal", "a.b:=fatal"),
    ],
)
def test_levels_are_read_as_rcutils_writes_them(given: str, taken: str) -> None:
    assert log_level(given) == taken


@pytest.mark.parametrize("given", ["loud", ":=info", "x:=", "x:=wran"])
def test_a_bad_level_is_a_usage_error_that_lists_the_levels(given: str) -> None:
    with pytest.raises(UsageError) as caught:
        log_level(given)
    assert "LEVEL one of debug, info, warn, error, fatal" in str(caught.value)


def test_mlaunchs_own_lines_follow_the_level() -> None:
    assert own_log_level(["info", "nav2:=debug", "launch:=error"]) == "error"
    assert own_log_level(["nav2:=debug"]) is None
    for level, shown in [
        ("warn", ["WARNING", "ERROR"]),
        ("debug", ["DEBUG", "INFO", "WARNING", "ERROR"]),
        (None, ["INFO", "WARNING", "ERROR"]),
    ]:
        seen: list[bytes] = []
        printer = Printer(out=seen.append, level=level)
        for severity in ("DEBUG", "INFO", "WARNING", "ERROR"):
            printer.message(severity, "launch", "said")
        printed = b"".join(seen).decode()
        assert [line.split("]")[0][1:] for line in printed.splitlines()] == shown, level
        printer.close()
