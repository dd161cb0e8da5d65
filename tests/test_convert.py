"""mlaunch convert: the ROS 2 file it writes resolves to the same plan as the ROS 1 file.

Every ROS 1 file here is converted to .launch.py, .launch.yaml and .launch.xml; each result is
loaded by mlaunch's own ROS 2 frontends and resolved with the same arguments as the original.
The processes must be equal (argv with params files by content, env changes, output, respawn,
required). Also: what the files say (arguments, comments), and the command line.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from test_roslaunch import fresh_packages, package, plan_of, summarize, write

from mlaunch.cli import main as mlaunch_main
from mlaunch.commands import convert

__all__ = ["fresh_packages"]  # the autouse fixture, used here too

FORMATS = ("py", "yaml", "xml")

PART = """
<launch>
  <arg name="who"/>
  <arg name="speed" default="1"/>
  <node pkg="mlaunch_demo" type="listener" name="part_listener" args="$(dirname)">
    <param name="speed" value="$(arg speed)"/>
    <param name="who" value="$(arg who)"/>
  </node>
</launch>
"""

MAIN = """
<launch>
  <arg name="robot" default="r1" doc="the robot's name"/>
  <arg name="rate" default="10"/>
  <arg name="sim" default="false"/>
  <arg name="mode" default="fast"/>
  <arg name="fixed" value="42"/>
  <param name="/use_sim_time" value="$(arg sim)"/>
  <param name="global_int" value="7"/>
  <remap from="chatter" to="chat"/>
  <env name="KS_ENV" value="$(arg robot)-$(optenv KS_MISSING none)"/>
  <node pkg="mlaunch_demo" type="talker" name="talker" output="screen" respawn="true"
        respawn_delay="2" args="--rate $(arg rate) 'two words' $(arg fixed)">
    <param name="a/b" type="double" value="3"/>
    <param name="~private" value="yes"/>
    <param name="as_str" type="str" value="true"/>
    <param name="computed" value="$(eval rate * 2)"/>
    <param name="is_fast" value="$(eval mode == 'fast' and not sim)"/>
    <param name="typed" type="int" value="$(arg rate)"/>
    <rosparam file="$(find ks_cfg)/ctrl.yaml" subst_value="true"/>
    <rosparam ns="inline">
      x: rad(pi/2)
      names: [a, b]
    </rosparam>
    <remap from="in" to="$(arg robot)/in"/>
    <env name="NODE_ENV" value="1"/>
  </node>
  <param name="late_global" value="after the talker"/>
  <group ns="$(arg robot)">
    <param name="ns_param" value="3.5"/>
    <node pkg="mlaunch_demo" type="listener" name="listener" required="true"
          launch-prefix="nice -n 5"/>
    <include file="$(dirname)/part.launch">
      <arg name="who" value="$(arg robot)"/>
    </include>
  </group>
  <group if="$(arg sim)">
    <param name="sim_only" value="true"/>
    <node pkg="mlaunch_demo" type="talker" name="sim_talker"/>
  </group>
  <node pkg="mlaunch_demo" type="listener" name="$(anon side_listener)" unless="$(arg sim)" ns="side"/>
  <node pkg="tf" type="static_transform_publisher" name="tf" args="0 0 0 0 0 0 a b 100"/>
  <test test-name="t" pkg="mlaunch_demo" type="talker"/>
</launch>
"""

TF_LINE = (
    MAIN.lstrip()
    .splitlines()
    .index(
        '  <node pkg="tf" type="static_transform_publisher" name="tf" args="0 0 0 0 0 0 a b 100"/>'
    )
    + 1
)
CASES = [
    {},
    {"sim": "true", "robot": "r9", "rate": "3", "mode": "slow"},
    {"rate": "4", "sim": "True", "mode": "fast"},
]


@pytest.fixture(autouse=True)
def static_transform_standin(monkeypatch: pytest.MonkeyPatch) -> None:
    """Plans here never start a process: the static_transform_publisher stand-in counts as
    available whether or not this machine has tf2_msgs, so ROS 1 and converted plans agree."""
    from mlaunch import standins

    monkeypatch.setattr(standins, "NEEDS", {})


@pytest.fixture
def system(tmp_path: Path) -> Path:
    """main.launch, part.launch and a config package in a source tree."""
    cfg = package(tmp_path, "ks_cfg")
    (cfg / "ctrl.yaml").write_text(
        "rate: 20\ngains: {kp: 1.5, ki: 0}\nframes: [base, odom]\nlabel: $(arg robot)\n"
    )
    write(tmp_path, "launch/part.launch", PART)
    return Path(write(tmp_path, "launch/main.launch", MAIN))


def converted(source: Path, fmt: str, output: Path | None = None) -> Path:
    out = output or source.with_name(source.name + "." + fmt)
    assert mlaunch_main(["convert", str(source), "--to", fmt, "-o", str(out)]) == 0
    return out


@pytest.mark.parametrize("fmt", FORMATS)
def test_conversion_resolves_to_the_same_plan(system: Path, fmt: str, tmp_path: Path) -> None:
    out = converted(system, fmt)
    for i, args in enumerate(CASES):
        ros1 = plan_of(str(system), args, temp=tmp_path / f"ros1-{i}")
        ros2 = plan_of(str(out), args, temp=tmp_path / f"ros2-{i}")
        assert summarize(ros2) == summarize(ros1), args
        names = {p.node.name for p in ros1.processes() if p.node is not None}
        sim = args.get("sim", "false").lower() == "true"
        assert ("sim_talker" in names) is sim and len(names) == 5 and "tf" in names


def test_included_files_are_their_converted_twins_when_they_exist(
    system: Path, tmp_path: Path
) -> None:
    for fmt in FORMATS:
        before = converted(system, fmt).read_text()
        assert "part.launch is a ROS 1 file" in before
        twin = converted(system.with_name("part.launch"), fmt)
        after = converted(system, fmt).read_text()
        assert f"part.launch.{fmt}" in after and "part.launch is a ROS 1 file" not in after
        ros1 = plan_of(str(system), temp=tmp_path / f"a-{fmt}")
        ros2 = plan_of(str(system.with_name(f"main.launch.{fmt}")), temp=tmp_path / f"b-{fmt}")
        assert summarize(ros2) == summarize(ros1)
        twin.unlink()


def test_an_include_from_a_package_not_found_here_still_converts(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "i.launch",
        '<launch>\n  <include file="$(find not_here_pkg)/launch/x.launch"/>\n</launch>\n',
    )
    text = convert.convert(path, "py")
    assert 'AnyLaunchDescriptionSource([FindPackageShare("not_here_pkg"), "/launch/x.launch"])' in (
        text
    )
    assert "cannot check for a converted twin" in text and "not_here_pkg" in text


def test_output_elsewhere_keeps_dirname_pointing_at_the_source(
    system: Path, tmp_path: Path
) -> None:
    elsewhere = tmp_path / "out"
    elsewhere.mkdir()
    out = converted(system, "py", elsewhere / "main.launch.py")
    assert "ThisLaunchFileDir" not in out.read_text()
    assert repr(str(system.parent)).strip("'") in out.read_text()
    ros1 = plan_of(str(system), temp=tmp_path / "a")
    ros2 = plan_of(str(out), temp=tmp_path / "b")
    assert summarize(ros2) == summarize(ros1)


def test_python_output_is_idiomatic_and_commented(system: Path) -> None:
    text = converted(system, "py").read_text()
    compile(text, "main.launch.py", "exec")
    assert (
        'DeclareLaunchArgument("robot", default_value="r1", description="the robot\'s name")'
        in text
    )
    assert 'SetLaunchConfiguration("fixed", "42")' in text
    assert 'SetParameter(name="use_sim_time", value=LaunchConfiguration("sim"))' in text
    assert '"typed": ParameterValue(LaunchConfiguration("rate"), value_type=int)' in text
    assert "on_exit=Shutdown()" in text and 'prefix="nice -n 5"' in text
    assert 'PushROSNamespace(LaunchConfiguration("robot"))' in text
    lines = text.splitlines()
    # each warning is a comment right where it applies; the static transform is a live node
    # whatever this machine has installed (the file is for wherever it runs)
    at = next(i for i, line in enumerate(lines) if f"# main.launch:{TF_LINE}" in line)
    block = "\n".join(lines[at : at + 40])
    assert "WARNING: the period (100 ms) of ROS 1 tf static_transform_publisher" in block
    assert '        package="tf2_ros",' in block and '            "--frame-id",' in block
    assert "is not installed" not in block
    assert "WARNING: rostest <test test-name='t'> is skipped" in text
    ruff = shutil.which("ruff", path=os.path.dirname(sys.executable))
    if ruff is not None:  # the dev tools are installed: the file is lint- and format-clean
        for check in (["check"], ["format", "--check"]):
            done = subprocess.run(
                [ruff, *check, "--isolated", "--line-length", "100", "-"],
                input=text,
                capture_output=True,
                text=True,
                check=False,
            )
            assert done.returncode == 0, done.stdout + done.stderr


def test_yaml_and_xml_outputs_are_commented_too(system: Path) -> None:
    yaml_text = converted(system, "yaml").read_text()
    assert f"# main.launch:{TF_LINE}: ROS 1 static_transform_publisher arguments" in yaml_text
    assert '    args: "--x 0 --y 0 --z 0 --yaw 0 --pitch 0 --roll 0 --frame-id a' in yaml_text
    xml_text = converted(system, "xml").read_text()
    assert f"<!-- main.launch:{TF_LINE}: ROS 1 static_transform_publisher arguments" in xml_text
    assert (
        'args="--x 0 --y 0 --z 0 --yaw 0 --pitch 0 --roll 0 --frame-id a --child-frame-id b"'
        in (xml_text)
    )
    assert '<arg name="robot" default="r1" description="the robot&apos;s name"/>' in xml_text or (
        '<arg name="robot" default="r1" description="the robot\'s name"/>' in xml_text
    )


def test_eval_arguments_keep_their_type_in_python_expressions(tmp_path: Path) -> None:
    path = Path(
        write(
            tmp_path,
            "e.launch",
            """
            <launch>
              <arg name="n" default="3"/>
              <arg name="flag" default="false"/>
              <arg name="word" default="abc"/>
              <node pkg="mlaunch_demo" type="talker" name="t">
                <param name="sum" value="$(eval n + arg('n') * 2)"/>
                <param name="both" value="$(eval flag or word == 'abc')"/>
                <param name="text" value="$(eval word.upper() + optenv('NO_SUCH_VAR', '!'))"/>
              </node>
            </launch>
            """,
        )
    )
    for fmt in FORMATS:
        out = converted(path, fmt)
        for i, args in enumerate([{}, {"n": "2.5", "flag": "true", "word": "xyz"}]):
            ros1 = plan_of(str(path), args, temp=tmp_path / f"a-{fmt}-{i}")
            ros2 = plan_of(str(out), args, temp=tmp_path / f"b-{fmt}-{i}")
            assert summarize(ros2) == summarize(ros1), (fmt, args)


def test_what_yaml_and_xml_cannot_write_is_a_clear_error(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "q.launch",
        '<launch>\n  <node pkg="mlaunch_demo" type="talker" name="t">\n'
        '    <param name="x" command="echo $(optenv NOPE a b)"/>\n  </node>\n</launch>\n',
    )
    with pytest.raises(convert.ConversionError, match=r"needs quotes .*--to py"):
        convert.convert(path, "xml")
    assert 'EnvironmentVariable("NOPE", default_value="a b")' in convert.convert(path, "py")


def test_deep_nesting_converts_to_xml_and_yaml_and_is_refused_for_python(tmp_path: Path) -> None:
    # 300 nested groups: past Python's default recursion limit (a RecursionError before).
    body = '<node pkg="mlaunch_demo" type="talker" name="t"/>'
    for _ in range(300):
        body = f"<group>{body}</group>"
    source = Path(write(tmp_path, "deep.launch", f"<launch>{body}</launch>\n"))
    ros1 = plan_of(str(source), temp=tmp_path / "ros1")
    for fmt in ("xml", "yaml"):
        ros2 = plan_of(str(converted(source, fmt)), temp=tmp_path / fmt)
        assert summarize(ros2) == summarize(ros1), fmt
    # One Python expression cannot nest 300 calls (~200 parentheses): said, not written.
    with pytest.raises(convert.ConversionError, match=r"would not compile .*\(--to xml") as err:
        convert.convert(str(source), "py")
    assert err.value.where == str(source)


def test_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, "c.launch", '<launch>\n  <arg name="x" default="1"/>\n</launch>\n')
    assert mlaunch_main(["convert", path]) == 0  # Python on standard output by default
    assert "def generate_launch_description() -> LaunchDescription:" in capsys.readouterr().out
    out = tmp_path / "c.launch.xml"
    assert mlaunch_main(["convert", path, "-o", str(out)]) == 0  # the format from the suffix
    assert out.read_text().startswith('<?xml version="1.0"?>')
    assert mlaunch_main(["convert", str(tmp_path / "missing.launch")]) == 2
    assert "mlaunch: error: launch file" in capsys.readouterr().err
    assert mlaunch_main(["convert", path, "-o", str(tmp_path / "no" / "dir.py")]) == 2
    assert "cannot write" in capsys.readouterr().err
    bad = write(tmp_path, "bad.launch", "<launch>\n  <machine name='m'/>\n</launch>\n")
    assert mlaunch_main(["convert", bad, "--to", "yaml"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "bad.launch:2: <machine>: missing required attribute 'address'" in err


def test_mlaunch_convert_subcommand_runs(tmp_path: Path) -> None:
    path = write(tmp_path, "s.launch", '<launch>\n  <arg name="x" default="1"/>\n</launch>\n')
    done = subprocess.run(
        [sys.executable, "-m", "mlaunch", "convert", path, "--to", "yaml"],
        capture_output=True,
        text=True,
        check=False,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert (
        textwrap.dedent(
            """
        launch:
        # s.launch:2
        - arg:
            name: x
            default: "1"
        """
        )
        in "\n" + done.stdout
    )
