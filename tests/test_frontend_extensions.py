"""Tags and substitutions a package registers with ``expose_action`` / ``expose_substitution``
work in its XML and YAML files under ``mlaunch FILE``: found through the entry point
``launch.frontend.launch_extension`` as ros2 launch finds them, or registered by an import of
the package in a Python launch file; their mistakes are located like the built-in tags'."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

from mlaunch.plan.text import rel

EXTENSION = """
from launch.action import Action
from launch.actions import ExecuteProcess
from launch.frontend import expose_action, expose_substitution
from launch.substitution import Substitution
from launch.utilities import perform_substitutions


@expose_substitution("upper")
class Upper(Substitution):
    def __init__(self, value):
        self.value = value

    @classmethod
    def parse(cls, data):
        if len(data) != 1:
            raise TypeError("upper takes one argument")
        return cls, {"value": data[0]}

    def perform(self, context):
        return perform_substitutions(context, self.value).upper()


@expose_action("shout")
class Shout(Action):
    def __init__(self, *, text, times=1, **kwargs):
        super().__init__(**kwargs)
        self.text = text
        self.times = times

    @classmethod
    def parse(cls, entity, parser):
        _, kwargs = super().parse(entity, parser)
        kwargs["text"] = parser.parse_substitution(entity.get_attr("text"))
        times = entity.get_attr("times", data_type=int, optional=True, can_be_str=False)
        if times is not None:
            kwargs["times"] = times
        return cls, kwargs

    def execute(self, context):
        text = perform_substitutions(context, self.text)
        return [ExecuteProcess(cmd=["echo"] + [text] * self.times, name="shout")]


@expose_action("wrap")
class Wrap(Action):
    \"\"\"Its child actions, built-in or not, parsed by the parser it is given.\"\"\"

    def __init__(self, *, actions, **kwargs):
        super().__init__(**kwargs)
        self.actions = actions

    @classmethod
    def parse(cls, entity, parser):
        _, kwargs = super().parse(entity, parser)
        kwargs["actions"] = [parser.parse_action(child) for child in entity.children]
        return cls, kwargs

    def execute(self, context):
        return list(self.actions)


@expose_action("explode")
class Explode(Action):
    @classmethod
    def parse(cls, entity, parser):
        _, kwargs = super().parse(entity, parser)
        return cls, kwargs

    def execute(self, context):
        raise RuntimeError("boom")
"""

XML = """\
<launch>
  <arg name="who" default="world"/>
  <group>
    <shout text="hi $(upper $(var who))" times="2" if="true"/>
  </group>
  <shout text="never" unless="true"/>
</launch>
"""

YAML = """\
launch:
- arg: {name: who, default: world}
- group:
    children:
    - shout: {text: "hi $(upper $(var who))", times: 2, if: "true"}
- shout: {text: never, unless: "true"}
"""


def extension(root: Path, *, entry_point: bool) -> dict[str, str]:
    """The package ``shout_ext`` under ``root`` (with its entry point when asked); the env."""
    (root / "shout_ext").mkdir()
    (root / "shout_ext" / "__init__.py").write_text(EXTENSION)
    if entry_point:
        info = root / "shout_ext-1.0.dist-info"
        info.mkdir()
        (info / "METADATA").write_text("Metadata-Version: 2.1\nName: shout_ext\nVersion: 1.0\n")
        (info / "entry_points.txt").write_text(
            "[launch.frontend.launch_extension]\nshout_ext = shout_ext\n"
        )
    return clean_env(PYTHONPATH=str(root))


def printed(path: Path, env: dict[str, str], *args: str) -> str:
    done = run_mlaunch(str(path), "--print", *args, env=env)
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize(("name", "text"), [("s.launch.xml", XML), ("s.launch.yaml", YAML)])
def test_entry_point_extension_tags_and_substitutions(tmp_path: Path, name: str, text: str) -> None:
    (tmp_path / "site").mkdir()
    env = extension(tmp_path / "site", entry_point=True)
    path = tmp_path / name
    path.write_text(text)
    out = printed(path, env, "who:=ros")
    assert "argv:    echo 'hi ROS' 'hi ROS'" in out
    assert "never" not in out
    assert "1 process(es)" in out


def test_import_in_a_python_launch_file_registers_them(tmp_path: Path) -> None:
    site = tmp_path / "site"
    site.mkdir()
    env = extension(site, entry_point=False)
    (tmp_path / "inner.launch.yaml").write_text(YAML)
    path = tmp_path / "outer.launch.py"
    path.write_text(
        textwrap.dedent(
            """\
            import shout_ext  # registers <shout> and $(upper)
            from launch import LaunchDescription
            from launch.actions import IncludeLaunchDescription
            from launch.launch_description_sources import AnyLaunchDescriptionSource
            from launch.substitutions import ThisLaunchFileDir


            def generate_launch_description():
                return LaunchDescription([
                    IncludeLaunchDescription(
                        AnyLaunchDescriptionSource([ThisLaunchFileDir(), '/inner.launch.yaml'])
                    )
                ])
            """
        )
    )
    assert "argv:    echo 'hi WORLD' 'hi WORLD'" in printed(path, env)


WRAPPED = {
    "w.launch.xml": """\
<launch>
  <wrap>
    <executable cmd="echo $(upper in)" name="inner"/>
    <shout text="x"/>
  </wrap>
</launch>
""",
    "w.launch.yaml": """\
launch:
- wrap:
  - executable: {cmd: "echo $(upper in)", name: inner}
  - shout: {text: x}
""",
}


@pytest.mark.parametrize("name", sorted(WRAPPED))
def test_an_exposed_tag_holds_built_in_and_exposed_children(tmp_path: Path, name: str) -> None:
    (tmp_path / "site").mkdir()
    env = extension(tmp_path / "site", entry_point=True)
    path = tmp_path / name
    path.write_text(WRAPPED[name])
    out = printed(path, env)
    assert "argv:    echo IN" in out and "argv:    echo x" in out
    # --print names files as they read from here (relative when the clone is near the tmp dir)
    assert f"inner-1   {rel(str(path))}:3" in out


def test_check_accepts_what_installed_packages_expose(tmp_path: Path) -> None:
    (tmp_path / "site").mkdir()
    env = extension(tmp_path / "site", entry_point=True)
    path = tmp_path / "s.launch.xml"
    path.write_text(XML)
    done = run_mlaunch(str(path), "--check", env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    done = run_mlaunch(str(path), "--check", env=clean_env())
    assert done.returncode == 1
    assert f"{path}:4:5: Jazzy has no tag 'shout'" in done.stdout


def test_without_the_package_the_tag_is_unknown(tmp_path: Path) -> None:
    path = tmp_path / "s.launch.xml"
    path.write_text(XML)
    done = run_mlaunch(str(path), "--print", env=clean_env())
    assert done.returncode == 2
    assert f"{path}:4:5: <shout>: unknown tag 'shout'" in done.stderr


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("<shout/>", "2:3: <shout>: missing required attribute 'text'"),
        ('<shout text="x" loud="1"/>', "2:25: <shout>: unknown attribute 'loud'"),
        (
            '<shout text="x" times="many"/>',
            "2:26: <shout>: attribute 'times' is 'many', which is not int",
        ),
        ('<shot text="x"/>', "2:3: <shot>: unknown tag 'shot' (did you mean 'shout'?)"),
        ('<log message="$(upper a b)"/>', "2:17: <log>: $(upper): TypeError: upper takes one"),
        ('<log message="$(uper a)"/>', "(did you mean 'upper'?)"),
    ],
)
def test_extension_mistakes_are_located(tmp_path: Path, body: str, message: str) -> None:
    site = tmp_path / "site"
    site.mkdir()
    env = extension(site, entry_point=True)
    path = tmp_path / "e.launch.xml"
    path.write_text(f"<launch>\n  {body}\n</launch>\n")
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert message in done.stderr, done.stderr
    assert done.stderr.startswith(f"mlaunch: error: {path}:")


def test_an_exposed_action_that_raises_is_located_not_a_crash(tmp_path: Path) -> None:
    site = tmp_path / "site"
    site.mkdir()
    env = extension(site, entry_point=True)
    path = tmp_path / "x.launch.xml"
    path.write_text("<launch>\n  <explode/>\n</launch>\n")
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2, done.stderr
    assert f"{site}/shout_ext/__init__.py:" in done.stderr
    assert f"RuntimeError in Explode: boom (the action written at {path}:2)" in done.stderr


def test_a_launch_file_action_that_raises_is_located(tmp_path: Path) -> None:
    path = tmp_path / "x.launch.py"
    path.write_text(
        textwrap.dedent(
            """\
            from launch import LaunchDescription
            from launch.action import Action


            class Broken(Action):
                def execute(self, context):
                    return {}["missing"]


            def generate_launch_description():
                return LaunchDescription([Broken()])
            """
        )
    )
    done = run_mlaunch(str(path), "--print", env=clean_env())
    assert done.returncode == 2, done.stderr
    assert f"mlaunch: error: {path}:7: KeyError in Broken: 'missing'" in done.stderr
