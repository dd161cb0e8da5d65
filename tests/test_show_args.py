"""``--show-args`` (issue 27, item 18): a default with substitutions shows its value where it
can be worked out (not wrapped code), a long one whole on its own line; an argument the
including file passes is not marked required."""

from __future__ import annotations

from pathlib import Path

from procutil import REPO, clean_env, run_mlaunch

CHILD = """\
<launch>
  <arg name="robot_name" description="the robot's name"/>
  <arg name="speed" default="1.0" description="how fast"/>
</launch>
"""
PARENT = """\
<launch>
  <arg name="map" default="$(dirname)/maps/a_rather_long_folder_name/warehouse_floor_2.yaml"/>
  <arg name="mode" description="what to do"/>
  <include file="$(dirname)/child.launch.xml">
    <arg name="robot_name" value="r1"/>
  </include>
</launch>
"""


def test_show_args_is_readable_and_knows_what_the_parent_passes(tmp_path: Path) -> None:
    (tmp_path / "child.launch.xml").write_text(CHILD)
    parent = tmp_path / "parent.launch.xml"
    parent.write_text(PARENT)
    done = run_mlaunch(str(parent), "--show-args", env=clean_env(COLUMNS="100"))
    assert done.returncode == 0, done.stderr
    rows = {line.split()[0]: line for line in done.stdout.splitlines()[4:] if line.strip()}
    assert rows["mode"].split()[1] == "(required)"
    assert rows["robot_name"].split()[1:4] == ["(passed", "by", "parent.launch.xml:4)"]
    assert rows["speed"].split()[1] == "'1.0'"
    assert rows["map"].split()[1] == "(below)"
    assert rows["default:"].split()[1] == (
        f"'{tmp_path}/maps/a_rather_long_folder_name/warehouse_floor_2.yaml'"
    ), done.stdout


def test_a_package_path_default_is_shown_as_the_path() -> None:
    done = run_mlaunch(
        str(REPO / "launches" / "jtbot_sim.launch.py"), "--show-args", env=clean_env()
    )
    assert done.returncode == 0, done.stderr
    assert "PathJoin(" not in done.stdout and "FindPackageShare" not in done.stdout
    assert f"default: '{REPO}/robots/jtbot_description/world/jt.world'" in done.stdout
