"""Shell completion, driven as bash drives it: argcomplete's environment protocol.

The shell runs ``mlaunch`` with ``_ARGCOMPLETE=1``, the line (``COMP_LINE``) and the cursor
(``COMP_POINT``), and reads the completions, separated by ``_ARGCOMPLETE_IFS``, from fd 8, or
from ``_ARGCOMPLETE_STDOUT_FILENAME`` as here.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from procutil import REPO, Running, clean_env, demo_package, mlaunch, run_mlaunch, wait_for

# bash's default COMP_WORDBREAKS: ':' and '=' break words, as in name:=value.
BASH_WORDBREAKS = " \t\n\"'><=;|&(:"

DEMO_LAUNCH = """\
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import PathJoinSubstitution, ThisLaunchFileDir

def generate_launch_description():
    print('a launch file that talks while it loads')
    return LaunchDescription([
        DeclareLaunchArgument('speed', default_value='1.0'),
        DeclareLaunchArgument('mode', default_value='fast', choices=['fast', 'slow']),
        DeclareLaunchArgument('model', default_value='jt'),
        IncludeLaunchDescription(PythonLaunchDescriptionSource(
            PathJoinSubstitution([ThisLaunchFileDir(), 'inner.launch.py']))),
    ])
"""

INNER_LAUNCH = """\
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument

def generate_launch_description():
    return LaunchDescription([DeclareLaunchArgument('inner_rate', default_value='5')])
"""


@pytest.fixture
def workspace(tmp_path: Path) -> tuple[Path, dict[str, str]]:
    """Package ``demo`` installed with two launch files (and a file that is not one); the
    working folder to complete in, and the environment."""
    prefix = Path(demo_package(tmp_path))
    launch = prefix / "share/demo/launch"
    launch.mkdir()
    (launch / "demo.launch.py").write_text(DEMO_LAUNCH)
    (launch / "inner.launch.py").write_text(INNER_LAUNCH)
    (launch / "notes.txt").write_text("not a launch file\n")
    (prefix / "share/demo/rviz").mkdir()
    (prefix / "share/demo/rviz/view.launch.xml").write_text("<launch/>\n")
    here = tmp_path / "here"
    here.mkdir()
    (here / "dev.launch.py").write_text(DEMO_LAUNCH.replace("'inner.launch.py'", "'none.py'"))
    (here / "launches").mkdir()
    (here / "data.csv").write_text("")
    env = clean_env(AMENT_PREFIX_PATH=str(prefix), ROS_LOG_DIR=str(tmp_path / "log"))
    env.pop("MLAUNCH_PACKAGE_PATH", None)
    return here, env


def complete(
    line: str, cwd: Path, env: dict[str, str], tmp_path: Path, start: int = 1
) -> list[str]:
    """What ``mlaunch`` offers bash for ``line`` with the cursor at its end (``start``: the
    word mlaunch's own begin at, 3 for ``python -m mlaunch``)."""
    out = tmp_path / "completions"
    env = {
        **env,
        "_ARGCOMPLETE": str(start),
        "_ARGCOMPLETE_SUPPRESS_SPACE": "1",
        "_ARGCOMPLETE_COMP_WORDBREAKS": BASH_WORDBREAKS,
        "_ARGCOMPLETE_STDOUT_FILENAME": str(out),
        "COMP_LINE": line,
        "COMP_POINT": str(len(line)),
        "COMP_TYPE": "9",
    }
    done = subprocess.run(
        [sys.executable, "-m", "mlaunch"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=30,
        stdin=subprocess.DEVNULL,
    )
    assert done.returncode == 0, done.stderr
    text = out.read_text()
    return text.split("\013") if text else []


def test_first_word_offers_subcommands_packages_and_launch_files(
    workspace: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    here, env = workspace
    assert complete("mlaunch de", here, env, tmp_path) == ["demo", "dev.launch.py"]
    assert complete("mlaunch te", here, env, tmp_path) == ["test"]
    offered = complete("mlaunch ", here, env, tmp_path)
    assert {"test", "convert", "export", "ctl", "demo", "dev.launch.py", "launches/"} <= set(
        offered
    )
    assert "data.csv" not in offered  # not a launch file


def test_package_then_its_launch_files(
    workspace: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    here, env = workspace
    assert complete("mlaunch demo ", here, env, tmp_path) == [
        "demo.launch.py",
        "inner.launch.py",
        "view.launch.xml",
    ]
    assert complete("mlaunch demo v", here, env, tmp_path) == ["view.launch.xml"]


def test_launch_arguments_of_the_file_and_its_includes(
    workspace: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    here, env = workspace
    every = ["speed:=", "mode:=", "model:=", "inner_rate:="]
    assert complete("mlaunch demo demo.launch.py ", here, env, tmp_path) == every
    assert complete("mlaunch demo demo.launch.py mo", here, env, tmp_path) == ["mode:=", "model:="]
    # Already given: not offered again.
    line = "mlaunch demo demo.launch.py speed:=2 "
    assert complete(line, here, env, tmp_path) == every[1:]
    # A path works as well as a package; the value of an argument with choices completes too
    # (bash breaks words at ':' and '=', so the shell gets the part after them).
    assert complete("mlaunch ./dev.launch.py sp", here, env, tmp_path) == ["speed:="]
    assert complete("mlaunch dev.launch.py mode:=", here, env, tmp_path) == ["fast", "slow"]
    assert complete("mlaunch dev.launch.py mode:=s", here, env, tmp_path) == ["slow"]


def test_subcommands_and_options(workspace: tuple[Path, dict[str, str]], tmp_path: Path) -> None:
    here, env = workspace
    assert complete("mlaunch dev.launch.py --viewer-p", here, env, tmp_path) == ["--viewer-port"]
    assert complete("mlaunch dev.launch.py --color ", here, env, tmp_path) == [
        "auto",
        "always",
        "never",
    ]
    offered = complete("mlaunch test dev.launch.py --expect-t", here, env, tmp_path)
    assert sorted(offered) == ["--expect-tf", "--expect-topic"]
    offered = complete("mlaunch test dev.launch.py --expect-to", here, env, tmp_path)
    assert offered == ["--expect-topic"]
    assert complete("mlaunch test dev.launch.py sp", here, env, tmp_path) == ["speed:="]
    assert complete("mlaunch export dev.launch.py --to", here, env, tmp_path) == ["--to"]
    (here / "old.launch").write_text("<launch/>\n")
    assert complete("mlaunch convert o", here, env, tmp_path) == ["old.launch"]
    assert complete("mlaunch ctl re", here, env, tmp_path) == ["restart"]
    assert complete("mlaunch ctl stop ", here, env, tmp_path) == []
    line = "python3 -m mlaunch test dev.launch.py --expect-to"
    assert complete(line, here, env, tmp_path, start=3) == ["--expect-topic"]


TWO_SLEEPERS = f"""\
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    sleep = [{sys.executable!r}, '-c', 'import time; time.sleep(60)']
    return LaunchDescription([
        ExecuteProcess(cmd=sleep, name='left'),
        ExecuteProcess(cmd=sleep, name='right'),
    ])
"""


def test_ctl_completes_the_live_runs_labels(
    workspace: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    here, env = workspace
    path = here / "two.launch.py"
    path.write_text(TWO_SLEEPERS)
    run = Running(mlaunch(str(path)), env=env, cwd=str(here))
    try:
        run.wait_for(r"\[right-2\]: process started", timeout=30)
        # The control socket opens on the loop's first turn: ask until the run answers.
        labels = wait_for(
            lambda: complete("mlaunch ctl stop ", here, env, tmp_path) or None,
            20,
            "the run's labels",
        )
        assert labels == ["left-1", "right-2"]
        assert complete("mlaunch ctl restart r", here, env, tmp_path) == ["right-2"]
        assert complete("mlaunch ctl list ", here, env, tmp_path) == []
        assert complete("mlaunch ctl stop left-1 ", here, env, tmp_path) == []
    finally:
        run.signal(signal.SIGINT)
        run.finish(timeout=20)
        run.kill()


def test_a_broken_launch_file_completes_nothing(
    workspace: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    here, env = workspace
    (here / "broken.launch.py").write_text("def generate_launch_description(:\n")
    assert complete("mlaunch broken.launch.py ", here, env, tmp_path) == []


def test_a_launch_never_loads_argcomplete(tmp_path: Path) -> None:
    """Completion costs a normal launch one environment lookup: argcomplete is not imported."""
    path = tmp_path / "one.launch.py"
    path.write_text(
        textwrap.dedent(
            f"""
            from launch import LaunchDescription
            from launch.actions import ExecuteProcess

            def generate_launch_description():
                return LaunchDescription([ExecuteProcess(cmd=[{sys.executable!r}, '-c', 'pass'])])
            """
        )
    )
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "log"), PYTHONPROFILEIMPORTTIME="1")
    done = run_mlaunch(str(path), env=env)
    assert done.returncode == 0, done.stderr
    assert "mlaunch.engine.supervisor" in done.stderr  # the import log is there
    assert "argcomplete" not in done.stderr and "mlaunch.cli.completion" not in done.stderr


def test_setup_turns_completion_on_in_the_venv(tmp_path: Path) -> None:
    """./scripts/setup hooked argcomplete into .venv's activate: bash completes mlaunch then."""
    activate = REPO / ".venv" / "bin" / "activate"
    if not activate.exists():
        pytest.skip("no .venv here: ./scripts/setup makes it")
    done = subprocess.run(
        ["bash", "-c", f"source {activate} && complete -p mlaunch"],
        capture_output=True,
        text=True,
        timeout=30,
        env=clean_env(),
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().endswith("-F _python_argcomplete mlaunch"), done.stdout
