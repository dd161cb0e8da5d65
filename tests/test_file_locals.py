"""An include's file locals (ThisLaunchFileDir, $(dirname) ...): Jazzy's by default (they stay the
included file's for the include's arguments and what follows, ros2/launch#618), the includer's
on request (--scoped-file-locals, the file's comment) and in ROS 1 files and their conversions.
tests/test_group_returns.py holds the resolver's default and opt-in; the conformance cases
file_locals.launch.{py,xml} hold the default to the reference."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_roslaunch import fresh_packages as fresh_packages  # autouse: this test's packages
from test_roslaunch import plan_of, write

from mlaunch.app.options import parse_options
from mlaunch.cli import main as mlaunch_main
from mlaunch.launch.actions import IncludeLaunchDescription, LaunchDescription, LogInfo
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.launch_description_sources import LaunchDescriptionSource
from mlaunch.launch.substitutions import ThisLaunchFileDir, perform_substitutions
from mlaunch.plan.steps import Log
from mlaunch.resolve.resolver import ResolveOptions, resolve

ROS1_MAIN = """
<launch>
  <include file="$(dirname)/parts/part.launch">
    <arg name="given" value="$(dirname)"/>
  </include>
  <node pkg="mlaunch_demo" type="talker" name="after" args="$(dirname)"/>
</launch>
"""
ROS1_PART = """
<launch>
  <arg name="given"/>
  <node pkg="mlaunch_demo" type="listener" name="part" args="$(arg given) $(dirname)"/>
</launch>
"""


@pytest.fixture
def ros1_main(tmp_path: Path) -> Path:
    write(tmp_path, "parts/part.launch", ROS1_PART)
    return Path(write(tmp_path, "main.launch", ROS1_MAIN))


def _argvs(path: Path, temp: Path) -> list[tuple[str, ...]]:
    """Each process's arguments before its ROS ones."""
    argvs = [spec.argv[1:] for spec in plan_of(str(path), temp=temp).processes()]
    return [argv[: argv.index("--ros-args")] for argv in argvs]


def test_a_ros1_include_keeps_roslaunch_dirname(ros1_main: Path, tmp_path: Path) -> None:
    """roslaunch: $(dirname) in an include's arg and after the include is the includer's."""
    here, parts = str(tmp_path), str(tmp_path / "parts")
    assert _argvs(ros1_main, tmp_path / "p") == [(here, parts), (here,)]


@pytest.mark.parametrize("fmt", ["py", "xml", "yaml"])
def test_a_converted_ros1_file_keeps_them_by_its_comment(
    ros1_main: Path, tmp_path: Path, fmt: str
) -> None:
    out = ros1_main.with_name(f"main.launch.{fmt}")
    assert mlaunch_main(["convert", str(ros1_main), "--to", fmt, "-o", str(out)]) == 0
    text = out.read_text()
    assert "mlaunch: scoped-file-locals" in text
    ros1 = _argvs(ros1_main, tmp_path / "a")
    assert _argvs(out, tmp_path / "b") == ros1
    # Without the comment the converted file means what it means under ros2 launch.
    bare = out.with_name(f"bare.launch.{fmt}")
    bare.write_text(text.replace("mlaunch: scoped-file-locals", "(removed)"))
    parts = str(tmp_path / "parts")
    assert _argvs(bare, tmp_path / "c") == [(parts, parts), (parts,)]


def test_the_option_reaches_the_resolver() -> None:
    assert parse_options(["x.launch.py", "--scoped-file-locals"]).scoped_file_locals
    assert not parse_options(["x.launch.py"]).scoped_file_locals


def _include_then_log(tmp_path: Path) -> tuple[IncludeLaunchDescription, LogInfo]:
    child = tmp_path / "sub" / "child.launch.py"
    child.parent.mkdir()
    child.write_text("")
    source = LaunchDescriptionSource(LaunchDescription(), str(child))
    return IncludeLaunchDescription(source), LogInfo(msg=[ThisLaunchFileDir()])


def test_a_bare_context_keeps_launchs_rule_or_scopes_on_request(tmp_path: Path) -> None:
    include, _ = _include_then_log(tmp_path)
    context = LaunchContext()
    context.extend_locals({"current_launch_file_directory": "/includer"})
    include.visit(context)
    assert perform_substitutions(context, [ThisLaunchFileDir()]) == str(tmp_path / "sub")
    include.keep_file_locals = True
    context.extend_locals({"current_launch_file_directory": "/includer"})
    context.planner.visit(include)
    assert perform_substitutions(context, [ThisLaunchFileDir()]) == "/includer"


def test_the_warning_is_said_once_per_place(tmp_path: Path) -> None:
    include, log = _include_then_log(tmp_path)
    log.origin = f"{tmp_path / 'parent.launch.py'}:3"
    description = LaunchDescription([include, log, log])
    plan = resolve(description, path=str(tmp_path / "parent.launch.py"), arguments={}, environ={})
    assert [s.message for s in plan.steps if isinstance(s, Log)] == [str(tmp_path / "sub")] * 2
    (warning,) = [w for w in plan.warnings if "ThisLaunchFileDir" in w]
    assert warning.startswith(f"{tmp_path / 'parent.launch.py'}:3: ThisLaunchFileDir gives")
    options = ResolveOptions(scoped_file_locals=True)
    plan = resolve(
        description,
        path=str(tmp_path / "parent.launch.py"),
        arguments={},
        environ={},
        options=options,
    )
    assert [s.message for s in plan.steps if isinstance(s, Log)] == [str(tmp_path)] * 2
