"""A misspelled name gets a "did you mean" (issue 27, item 18): a ``$(var ...)``, a package, a
launch file (a path, or one in a package) and a topic ``mlaunch test`` expects."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from procutil import clean_env, install_package, run_mlaunch
from test_smoke_rate import Graph

from mlaunch.smoke.expectations import parse_target
from mlaunch.smoke.watch import GraphProbe


def _error(done: Any) -> str:
    assert done.returncode == 2, done.stdout + done.stderr
    (line,) = done.stderr.strip().splitlines()
    return str(line)


def test_a_misspelled_var_names_the_declared_one(tmp_path: Path) -> None:
    xml = tmp_path / "robot.launch.xml"
    xml.write_text(
        '<launch>\n  <arg name="robot_name" default="r1"/>\n'
        '  <log message="$(var robot_nme)"/>\n</launch>\n'
    )
    line = _error(run_mlaunch(str(xml), env=clean_env()))
    assert line == (
        f"mlaunch: error: {xml}:3: LogInfo: launch configuration 'robot_nme' does not exist"
        " (did you mean 'robot_name'?)"
    )


def test_a_misspelled_package_or_launch_file_names_the_close_one(tmp_path: Path) -> None:
    prefix = install_package(tmp_path / "install", "demo_pkg", {})
    launch = prefix / "share" / "demo_pkg" / "launch"
    launch.mkdir()
    (launch / "talker.launch.py").write_text("")
    env = clean_env(AMENT_PREFIX_PATH=str(prefix))
    package = _error(run_mlaunch("demo_pgk", "talker.launch.py", env=env))
    assert package.startswith(
        "mlaunch: error: package 'demo_pgk' not found (did you mean 'demo_pkg'?)"
    ), package
    in_package = _error(run_mlaunch("demo_pkg", "talkr.launch.py", env=env))
    assert in_package.endswith("(did you mean 'talker.launch.py'?)"), in_package
    by_path = _error(run_mlaunch(str(launch / "talkr.launch.py"), env=env))
    assert by_path == (
        f"mlaunch: error: launch file '{launch}/talkr.launch.py' does not exist"
        f" (did you mean '{launch}/talker.launch.py'?)"
    )


def test_a_misspelled_expected_topic_names_the_one_in_the_graph() -> None:
    graph: Any = Graph([])
    expectation = parse_target("topic", "/scna", "test")
    ((_, met, seen),) = GraphProbe(graph).check([expectation])
    assert not met
    assert seen == "not in the graph (no publisher or subscriber) (did you mean '/scan'?)"
