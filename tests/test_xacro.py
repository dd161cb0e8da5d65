"""xacro in-process (Command(['xacro ', ...])) against the ``xacro`` program, byte for byte.

The reference is the venv's own ``xacro`` program run as a subprocess, with an ament prefix for
``$(find)``; the in-process run must give the same stdout, stderr and exit status. Then: $(find)
through source packages, $(env) from the launch context, errors that name the xacro file and
line, and a launch file that calls xacro's Python API itself (the jtbot seed does).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
import xacro

from mlaunch import readers
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.substitutions import Command, perform
from mlaunch.launch.substitutions.command import IN_PROCESS_COMMANDS
from mlaunch.launch_ros import xacro as in_process
from mlaunch.plan.errors import SubstitutionFailure
from mlaunch.plan.steps import Log
from mlaunch.resolve.resolver import ResolveOptions, resolve
from mlaunch.ros import packages

REPO = Path(__file__).resolve().parent.parent
PROGRAM = Path(sys.executable).parent / "xacro"
JTBOT = REPO / "robots" / "jtbot_description" / "urdf" / "jtbot.urdf.xacro"
SMARTCAR_PKG = REPO / "robots" / "smartcar_description"
SMARTCAR = SMARTCAR_PKG / "urdf" / "smartcar.urdf.xacro"

BROKEN = """\
<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="a">
</robot>
"""
BAD_EXPRESSION = """\
<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="wheel" params="side"><link name="${side * missing}"/></xacro:macro>
  <xacro:wheel side="2"/>
</robot>
"""

pytestmark = pytest.mark.skipif(not PROGRAM.exists(), reason=f"no xacro program at {PROGRAM}")


@pytest.fixture(autouse=True)
def _fresh_packages() -> Iterator[None]:
    packages.forget_scans()
    yield
    packages.forget_scans()


@pytest.fixture
def ament_env(tmp_path: Path) -> dict[str, str]:
    """The environment of a real install: smartcar_description in an ament prefix."""
    prefix = tmp_path / "install"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "smartcar_description").write_text("")
    (prefix / "share" / "smartcar_description").symlink_to(SMARTCAR_PKG)
    environ = dict(os.environ)
    environ["AMENT_PREFIX_PATH"] = str(prefix)
    environ.pop("PYTHONWARNINGS", None)
    return environ


def program(args: list[str], environ: dict[str, str]) -> subprocess.CompletedProcess[bytes]:
    return subprocess.run(
        [str(PROGRAM), *args], env=environ, capture_output=True, check=False, timeout=60
    )


def here(args: list[str], environ: dict[str, str]) -> tuple[int, bytes, bytes]:
    rc, out, err = in_process.run_program(
        ["xacro", *args], environ, packages.index(environ=environ)
    )
    return rc, out.encode(), err.encode()


# --- identical to the program ------------------------------------------------------------------


@pytest.mark.parametrize(
    "args",
    [
        [str(JTBOT)],
        [str(JTBOT), "gazebo:=false"],
        ["--inorder", str(SMARTCAR)],
    ],
    ids=["jtbot", "jtbot-mapping", "smartcar-find-inorder"],
)
def test_output_is_byte_identical_to_the_program(args: list[str], ament_env: dict[str, str]):
    reference = program(args, ament_env)
    assert reference.returncode == 0, reference.stderr.decode()
    assert here(args, ament_env) == (reference.returncode, reference.stdout, reference.stderr)
    assert b"<robot" in reference.stdout


def test_output_file_option_writes_the_same_file(tmp_path: Path, ament_env: dict[str, str]):
    theirs, ours = tmp_path / "theirs.urdf", tmp_path / "ours.urdf"
    reference = program(["-o", str(theirs), str(JTBOT)], ament_env)
    rc, out, err = here(["-o", str(ours), str(JTBOT)], ament_env)
    assert (
        (rc, out, err)
        == (reference.returncode, reference.stdout, reference.stderr)
        == (
            0,
            b"",
            b"",
        )
    )
    assert ours.read_bytes() == theirs.read_bytes()


def test_failure_gives_the_same_stderr_and_status(tmp_path: Path, ament_env: dict[str, str]):
    bad = tmp_path / "broken.urdf.xacro"
    bad.write_text(BROKEN)
    reference = program([str(bad)], ament_env)
    assert reference.returncode == 2
    assert here([str(bad)], ament_env) == (2, b"", reference.stderr)
    usage = program([], ament_env)
    assert here([], ament_env) == (usage.returncode, usage.stdout, usage.stderr)


def test_state_is_restored_after_a_run(ament_env: dict[str, str]) -> None:
    before = (xacro.filestack, xacro.root_dir, list(xacro.all_includes))
    here(["--root-dir", "/tmp", str(JTBOT)], ament_env)
    assert (xacro.filestack, xacro.root_dir, list(xacro.all_includes)) == before
    assert xacro.substitution_args.os is os


# --- through Command, in a launch context ----------------------------------------------------


def test_command_runs_xacro_in_process_in_every_spelling(ament_env: dict[str, str]) -> None:
    import mlaunch.launch_ros.actions  # noqa: F401  (importing launch_ros registers it)

    assert IN_PROCESS_COMMANDS["xacro"] is in_process.run
    assert IN_PROCESS_COMMANDS["xacro.py"] is in_process.run
    reference = program([str(JTBOT)], ament_env).stdout.decode()
    ctx = LaunchContext(environment={"PATH": ""})  # no xacro on PATH: it cannot be spawned
    assert perform(ctx, Command(["xacro ", str(JTBOT)])) == reference
    assert perform(ctx, Command(["xacro", " ", str(JTBOT)])) == reference
    assert perform(ctx, Command(f"/opt/ros/jazzy/bin/xacro {JTBOT}")) == reference


def test_find_uses_source_packages_near_the_launch_file(ament_env: dict[str, str]) -> None:
    reference = program([str(SMARTCAR)], ament_env)
    ctx = LaunchContext(environment={"PATH": os.environ["PATH"]})  # no AMENT_PREFIX_PATH
    with ctx.file_locals(str(REPO / "launches" / "any.launch.py")):
        assert perform(ctx, Command(["xacro ", str(SMARTCAR)])) == reference.stdout.decode()


def test_env_comes_from_the_launch_context(tmp_path: Path) -> None:
    source = tmp_path / "env.urdf.xacro"
    source.write_text(
        '<?xml version="1.0"?>\n<robot name="$(env ROBOT_NAME)" '
        'xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="$(optenv LINK base)"/></robot>\n'
    )
    ctx = LaunchContext(environment={"ROBOT_NAME": "from_context"})
    assert "ROBOT_NAME" not in os.environ
    text = perform(ctx, Command(["xacro ", str(source)]))
    assert '<robot name="from_context">' in text and '<link name="base"/>' in text


def test_errors_name_the_file_line_and_xacros_message(tmp_path: Path) -> None:
    broken = tmp_path / "broken.urdf.xacro"
    broken.write_text(BROKEN)
    ctx = LaunchContext(environment={})
    with pytest.raises(SubstitutionFailure) as err:
        perform(ctx, Command(["xacro ", str(broken)]))
    assert err.value.message == (
        f"xacro failed on {broken}:4: XML parsing error: mismatched tag: line 4, column 2"
    )
    wrapper = tmp_path / "robot.urdf.xacro"
    wrapper.write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        f'  <xacro:include filename="{tmp_path / "macro.xacro"}"/>\n</robot>\n'
    )
    (tmp_path / "macro.xacro").write_text(BAD_EXPRESSION)
    with pytest.raises(SubstitutionFailure) as err:
        perform(ctx, Command(["xacro ", str(wrapper)]))
    assert err.value.message == (
        f"xacro failed on {tmp_path / 'macro.xacro'}: name 'missing' is not defined; when"
        " evaluating expression 'side * missing' (in macro wheel"
        f" ({tmp_path / 'macro.xacro'}); included from {wrapper})"
    )
    missing = packages.index(environ={}).searched()
    find = tmp_path / "find.urdf.xacro"
    find.write_text(
        '<?xml version="1.0"?>\n<robot name="r"><link name="$(find no_such_pkg)"/></robot>\n'
    )
    with pytest.raises(SubstitutionFailure) as err:
        perform(ctx, Command(["xacro ", str(find)]))
    assert err.value.message.startswith(
        f"xacro failed on {find}: PackageNotFoundError: package 'no_such_pkg' not found"
    )
    assert "--package-path DIR" in err.value.message and missing


def test_a_broken_robot_description_is_located_at_the_node(tmp_path: Path) -> None:
    from mlaunch.launch.actions import LaunchDescription
    from mlaunch.launch_ros.actions import Node
    from mlaunch.launch_ros.parameter_descriptions import ParameterValue

    broken = tmp_path / "broken.urdf.xacro"
    broken.write_text(BROKEN)
    node = Node(
        executable=sys.executable,
        parameters=[
            {"robot_description": ParameterValue(Command(["xacro ", str(broken)]), value_type=str)}
        ],
    )
    with pytest.raises(SubstitutionFailure) as err:
        resolve(
            LaunchDescription([node]),
            path=None,
            arguments={},
            environ={},
            options=ResolveOptions(temp_dir=str(tmp_path)),
        )
    assert err.value.where == node.origin
    assert str(err.value).endswith(
        f"xacro failed on {broken}:4: XML parsing error: mismatched tag: line 4, column 2"
    )


# --- the seed's own use of the xacro API -----------------------------------------------------


def test_launch_file_calling_xacro_directly_finds_packages(
    tmp_path: Path, ament_env: dict[str, str]
) -> None:
    repo = tmp_path / "repo"
    (repo / ".git").mkdir(parents=True)
    (repo / "robots").mkdir()
    (repo / "robots" / "smartcar_description").symlink_to(SMARTCAR_PKG)
    launch = repo / "launch" / "display.launch.py"
    launch.parent.mkdir()
    launch.write_text(
        textwrap.dedent(
            """\
            import os
            import xacro
            from launch import LaunchDescription
            from launch.actions import LogInfo
            from launch_ros.substitutions import FindPackageShare

            def generate_launch_description():
                pkg = FindPackageShare(package='smartcar_description').find('smartcar_description')
                doc = xacro.parse(open(os.path.join(pkg, 'urdf/smartcar.urdf.xacro')))
                xacro.process_doc(doc)
                return LaunchDescription([LogInfo(msg=doc.toxml())])
            """
        )
    )
    description = readers.load(str(launch))
    plan = resolve(
        description, path=str(launch), arguments={}, environ={}, options=ResolveOptions()
    )
    (text,) = [s.message for s in plan.steps if isinstance(s, Log)]
    # The same robot as the program makes with an ament prefix (layout and banner aside).
    reference = program([str(SMARTCAR)], ament_env).stdout.decode()
    assert "<robot" in text
    assert canonical(text) == canonical(reference)


def canonical(xml_text: str) -> str:
    import xml.etree.ElementTree as ET

    return ET.canonicalize(xml_text.split("?>", 1)[-1], strip_text=True)
