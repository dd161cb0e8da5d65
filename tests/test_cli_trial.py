"""What a new user's trial of every README feature found: each fix, pinned."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import sys
import textwrap
import urllib.request
from pathlib import Path

import pytest
from conftest import requires_rclpy
from ports import free_port
from procutil import Running, clean_env, demo_package, mlaunch, run_mlaunch

from mlaunch import __version__, standins
from mlaunch.app.options import VIEWER_PORT_ENV, build_parser
from mlaunch.engine.logfiles import DEFAULT_ROTATE_BYTES
from mlaunch.engine.output import Printer
from mlaunch.engine.process import Process
from mlaunch.parts import status
from mlaunch.plan.records import Output, Started
from mlaunch.plan.steps import ArgumentInfo, ProcessSpec
from mlaunch.resolve import describe
from mlaunch.standins.viewer_config import PORT_ENV

PY = sys.executable


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))


def test_launch_prefix_options_are_not_undeclared_arguments(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "p.launch.py"
    path.write_text(
        textwrap.dedent(
            f"""
            from launch import LaunchDescription
            from launch.actions import ExecuteProcess

            def generate_launch_description():
                return LaunchDescription([
                    ExecuteProcess(cmd=[{PY!r}, '-c', 'pass'], name='child', output='screen'),
                ])
            """
        )
    )
    done = run_mlaunch(
        str(path), "--launch-prefix", "env", "--launch-prefix-filter", "python.*", env=env
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "not declared" not in done.stdout + done.stderr
    # The prefix was applied: env ran the child.
    assert re.search(r"process started with pid \[\d+\]", done.stdout), done.stdout
    # An argument that really is undeclared still warns.
    done = run_mlaunch(str(path), "--launch-prefix", "env", "speed:=1", env=env)
    assert "argument 'speed' is not declared" in done.stdout


def test_status_falls_back_to_80x24_on_a_0x0_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(status.os, "get_terminal_size", lambda fd: os.terminal_size((0, 0)))
    assert status.terminal_size() == (80, 24)
    monkeypatch.setattr(status.os, "get_terminal_size", lambda fd: os.terminal_size((132, 50)))
    assert status.terminal_size() == (132, 50)


def test_show_args_keeps_long_defaults_whole(monkeypatch: pytest.MonkeyPatch) -> None:
    """A default longer than its column goes whole on a line of its own (it was wrapped in
    36-character pieces, hard to copy)."""
    long_default = "/opt/ros/jazzy/share/some_robot_description/urdf/robot_with_sensors.urdf"
    for columns in (80, 300, 0):
        monkeypatch.setattr(
            describe.os, "get_terminal_size", lambda fd, c=columns: os.terminal_size((c, 24))
        )
        text = describe.format_arguments(
            [ArgumentInfo("model", long_default, "the robot model", None, "test")]
        )
        assert "..." not in text
        row, below = text.splitlines()[4:6]
        assert row.split() == ["model", "(below)", "the", "robot", "model"]
        assert below.strip() == f"default: {long_default!r}"


def test_quiet_keeps_childrens_stderr() -> None:
    seen: list[bytes] = []
    printer = Printer(out=seen.append, quiet=True)
    printer.register("child-1", 0)
    printer.output("child-1", "stdout", "screen", b"chatter\n")
    printer.output("child-1", "stderr", "screen", b"it broke\n")
    printer.message("INFO", "launch", "process started")
    shown = b"".join(seen)
    assert b"[child-1] it broke\n" in shown
    assert b"chatter" not in shown and b"process started" not in shown
    printer.close()


def test_quiet_shows_ros_warnings_and_errors_whatever_the_stream() -> None:
    """rcutils logs INFO to stderr: -q kept it (10 of the seed's 13 lines were 'got segment')."""
    seen: list[bytes] = []
    printer = Printer(out=seen.append, quiet=True)
    printer.register("rsp-1", 0)
    stderr = (
        b"[INFO] [1700000000.1] [robot_state_publisher]: got segment base_link\n"
        b"\x1b[33m[WARN] [1700000000.2] [robot_state_publisher]: no joint states\x1b[0m\n"
        b"[DEBUG] [1700000000.3] [robot_state_publisher]: tick\n"
        b"Traceback (most recent call last):\n"
    )
    printer.output("rsp-1", "stderr", "screen", stderr)
    printer.output(
        "rsp-1", "stdout", "screen", b"[ERROR] [1.0] [x]: on stdout\n[INFO] [1.0] [x]: hi\n"
    )
    printer.output("rsp-1", "stdout", "screen", b"[ INFO] [1.0]: roslaunch's\n[ WARN] [1.0]: w\n")
    shown = b"".join(seen).decode()
    assert shown.splitlines() == [
        "[rsp-1] \x1b[33m[WARN] [1700000000.2] [robot_state_publisher]: no joint states\x1b[0m",
        "[rsp-1] Traceback (most recent call last):",
        "[rsp-1] [ERROR] [1.0] [x]: on stdout",
        "[rsp-1] [ WARN] [1.0]: w",
    ]
    printer.close()


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (
            ["talker.launch.py", "--use-sim-tme"],
            "mlaunch: error: unrecognized arguments: --use-sim-tme (did you mean"
            " '--use-sim-time'?); 'mlaunch --help' lists the options",
        ),
        (
            ["test", "talker.launch.py", "--hold", "x"],
            "mlaunch test: error: argument --hold: invalid float value: 'x'; 'mlaunch test"
            " --help' lists the options",
        ),
        (
            ["ctl", "--jsn", "list"],
            "mlaunch ctl: error: unrecognized arguments: --jsn (did you mean '--json'?);"
            " 'mlaunch ctl --help' lists the options",
        ),
        (
            ["ctl", "lst"],
            "mlaunch: error: no operation in 'lst' (did you mean 'list'?); valid: list, stop,"
            " start, restart, mute, unmute, logs, ",
        ),
    ],
    ids=["option", "test-value", "ctl-option", "ctl-operation"],
)
def test_an_option_error_is_one_line_with_the_fix(
    env: dict[str, str], argv: list[str], line: str
) -> None:
    """argparse printed its 9-line usage before the one line that matters, with no did-you-mean."""
    done = run_mlaunch(*argv, env=env)
    assert done.returncode == 2
    assert len(done.stderr.splitlines()) == 1, done.stderr
    assert done.stderr.startswith(line) if line.endswith(", ") else done.stderr == line + "\n"


def test_an_abbreviation_of_one_options_spellings_is_that_option(tmp_path: Path) -> None:
    """--show-arg was 'ambiguous' between --show-args and --show-arguments, the same option."""
    ns = build_parser().parse_args(["f.launch.py", "--show-arg"])
    assert ns.show_args
    with pytest.raises(SystemExit):
        build_parser().parse_args(["f.launch.py", "--s"])  # --show-args or --status: ambiguous


def test_print_names_no_params_file_that_is_gone_once_it_exits(
    tmp_path: Path, env: dict[str, str]
) -> None:
    """The text --print named /tmp/mlaunch-PID-.../launch_params_... files it had removed."""
    path = tmp_path / "params.launch.xml"
    path.write_text(
        '<launch><node pkg="demo" exec="talker" name="t">'
        '<param name="rate" value="5"/><param name="frame" value="map"/></node></launch>\n'
    )
    done = run_mlaunch(
        str(path), "--print", env={**env, "AMENT_PREFIX_PATH": demo_package(tmp_path)}
    )
    assert done.returncode == 0, done.stderr
    assert "/mlaunch-" not in done.stdout and "launch_params_" not in done.stdout, done.stdout
    assert "--params-file <params-file 1> --params-file <params-file 2>" in done.stdout
    assert "  files:   <params-file 1>, <params-file 2>: files mlaunch writes for the run" in (
        done.stdout
    )
    assert "  param:   rate = 5   [/**]   (params-file 1)" in done.stdout
    assert "  param:   frame = 'map'   [/**]   (params-file 2)" in done.stdout


@pytest.mark.parametrize("where", ["generate", "opaque"])
def test_an_unset_environment_variable_the_file_reads_is_named_as_one(
    tmp_path: Path, env: dict[str, str], where: str
) -> None:
    """'KeyError in generate_launch_description(): 'TURTLEBOT3_MODEL'' did not say what it was."""
    path = tmp_path / "tb3.launch.py"
    path.write_text(
        "import os\n"
        "from launch import LaunchDescription\n"
        "from launch.actions import OpaqueFunction\n"
        "def model(context):\n"
        "    return [] if os.environ['TURTLEBOT3_MODEL'] else []\n"
        "def generate_launch_description():\n"
        f"    {'model(None)' if where == 'generate' else 'pass'}\n"
        "    return LaunchDescription([OpaqueFunction(function=model)])\n"
    )
    env.pop("TURTLEBOT3_MODEL", None)
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 2
    assert f"{path}:5: " in done.stderr
    assert (
        "KeyError: 'TURTLEBOT3_MODEL' (TURTLEBOT3_MODEL is an environment variable the file"
        " reads, and it is not set: 'export TURTLEBOT3_MODEL=VALUE' first, or run"
        " 'TURTLEBOT3_MODEL=VALUE mlaunch ...')"
        in done.stderr.replace("KeyError in generate_launch_description(): ", "KeyError: ")
    ), done.stderr
    done = run_mlaunch(str(path), "--print", env={**env, "TURTLEBOT3_MODEL": "burger"})
    assert done.returncode == 0, done.stderr


def test_a_keyerror_of_a_dict_is_not_called_an_environment_variable() -> None:
    from mlaunch.plan.origin import unset_variable_hint

    empty: dict[str, str] = {}
    try:
        empty["HOME"]
    except KeyError as e:
        assert unset_variable_hint(e) == ""


def test_version_and_help_defaults(env: dict[str, str]) -> None:
    done = run_mlaunch("--version", env=env)
    assert done.returncode == 0
    assert done.stdout.strip() == f"mlaunch {__version__}"
    helped = run_mlaunch("--help", env={**env, "COLUMNS": "200"})
    assert "(default: auto" in helped.stdout
    mib = DEFAULT_ROTATE_BYTES // (1024 * 1024)
    assert f"(default: {DEFAULT_ROTATE_BYTES}, {mib} MiB)" in helped.stdout


@pytest.mark.parametrize("sub", [[], ["test"], ["convert"], ["export"]])
def test_help_has_no_restructuredtext_quoting(sub: list[str], env: dict[str, str]) -> None:
    done = run_mlaunch(*sub, "--help", env=env)
    assert done.returncode == 0, done.stderr
    assert "``" not in done.stdout


SIM_TIME_LAUNCH = """\
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, SetParameter

def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('use_sim_time', default_value='false'),
        DeclareLaunchArgument('sim', default_value='true'),
        SetParameter('use_sim_time', LaunchConfiguration('use_sim_time')),
        Node(package='demo', executable='talker',
             parameters=[{'use_sim_time': LaunchConfiguration('sim')}]),
    ])
"""


def test_use_sim_time_that_is_not_a_boolean_names_its_declaration(
    tmp_path: Path, env: dict[str, str]
) -> None:
    """ros2 launch passes use_sim_time:=maybe on and every node dies of a type error; mlaunch
    says so once, at the line that sets it, with the argument's declaration."""
    path = tmp_path / "sim.launch.py"
    path.write_text(SIM_TIME_LAUNCH)
    env = {**env, "AMENT_PREFIX_PATH": demo_package(tmp_path)}
    ok = run_mlaunch(str(path), "--print", "use_sim_time:=true", "sim:=False", env=env)
    assert ok.returncode == 0, ok.stderr
    done = run_mlaunch(str(path), "--print", "use_sim_time:=maybe", env=env)
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        f"mlaunch: error: {path}:10: SetParameter('use_sim_time'): parameter 'use_sim_time' is"
        " 'maybe', which every ROS node rejects at start-up (it must be a boolean); valid: true"
        f" or false (launch argument 'use_sim_time', declared at {path}:8)"
    ]
    # A node's own parameter, from another argument: 1 is an integer to ROS, not a boolean.
    done = run_mlaunch(str(path), "--print", "sim:=1", env=env)
    assert done.returncode == 2
    assert done.stderr.startswith(f"mlaunch: error: {path}:11: "), done.stderr
    assert "parameter 'use_sim_time' is 1," in done.stderr
    assert f"(launch argument 'sim', declared at {path}:9)" in done.stderr


def _viewer_process(output: str) -> Process:
    argv = (PY, "-m", "mlaunch.standins.viewer", "-d", "x.rviz")
    spec = ProcessSpec("rviz2-1", argv, {}, {}, output=output, standin="rviz2/rviz2")
    standins.equip(spec)  # what resolve gives a stand-in's spec
    process = Process(spec, 0)
    process.pid = 4242
    return process


@pytest.mark.parametrize(("output", "quiet"), [("log", False), ("log", True), ("screen", False)])
def test_the_viewers_address_is_said_once_in_every_mode(
    tmp_path: Path, output: str, quiet: bool
) -> None:
    seen: list[bytes] = []
    printer = Printer(out=seen.append, quiet=quiet, log_dir=str(tmp_path))
    viewer = _viewer_process(output)
    printer(Started(viewer))
    address = b"viewer: open http://127.0.0.1:41234/\n"
    printer(Output(viewer, "stdout", b"before\n" + address + b"after\n"))
    printer.close()
    shown = b"".join(seen).decode()
    assert shown.count("viewer: open") == 1
    assert "[INFO] [rviz2-1]: viewer: open http://127.0.0.1:41234/\n" in shown
    # The viewer's other stdout lines follow its output mode (and -q) as before.
    assert ("[rviz2-1] before" in shown) == (output == "screen" and not quiet)
    own = (tmp_path / "rviz2-1.log").read_text()
    assert own == "before\n" + address.decode() + "after\n"
    assert (tmp_path / "launch.log").read_text().count("viewer: open http://127.0.0.1:41234/") == 1


def test_other_processes_lines_like_the_address_are_theirs() -> None:
    seen: list[bytes] = []
    printer = Printer(out=seen.append, quiet=True)
    spec = ProcessSpec("rviz2-1", (PY, "-c", "print('viewer: open http://example/')"), {}, {})
    standins.equip(spec)  # not a stand-in: nothing to say for it
    assert spec.announce is None
    process = Process(spec, 0)
    printer(Started(process))
    printer(Output(process, "stdout", b"viewer: open http://example/\n"))
    assert b"".join(seen) == b""  # a plain child's stdout under -q: not said


def test_viewer_port_option_is_checked(env: dict[str, str]) -> None:
    for bad in ("http", "70000", "-1"):
        done = run_mlaunch("x.launch.py", "--viewer-port", bad, env=env)
        assert done.returncode == 2
        assert done.stderr == (
            f"mlaunch: error: --viewer-port is {bad!r}; valid: a port number 1..65535, or 0 for"
            " any free port\n"
        )
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        done = run_mlaunch("x.launch.py", "--viewer-port", str(port), env=env)
    assert done.returncode == 2
    assert done.stderr == (
        f"mlaunch: error: --viewer-port {port}: 127.0.0.1:{port} cannot be used (Address already"
        " in use); valid: a free port, or 0 for any free port\n"
    )
    assert VIEWER_PORT_ENV == PORT_ENV  # the name the viewer reads


VIEWER_LAUNCH = """\
from launch import LaunchDescription
from launch_ros.actions import Node

def generate_launch_description():
    return LaunchDescription([Node(package='rviz2', executable='rviz2', output='log')])
"""


@requires_rclpy
@pytest.mark.timeout(90)
def test_quiet_launch_shows_the_viewer_address_on_the_chosen_port(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    path = tmp_path / "view.launch.py"
    path.write_text(VIEWER_LAUNCH)
    port = free_port()
    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "logs")
    run = Running(mlaunch(str(path), "-q", "--viewer-port", str(port)), env=env, cwd=str(tmp_path))
    try:
        found = run.wait_for(r"\[INFO\] \[rviz2-1\]: viewer: open (http://\S+)\n", timeout=60)
        url = found.group(1)
        assert url == f"http://127.0.0.1:{port}/"
        with urllib.request.urlopen(url + "state.json", timeout=5) as reply:
            assert json.loads(reply.read())["fixed_frame"] == "odom"
        run.signal(signal.SIGINT)
        assert run.finish(timeout=15) == 130
    finally:
        run.kill()
    assert run.text.count("viewer: open") == 1, run.text
    assert "process started" not in run.text  # still quiet


def test_readme_exit_status_table_is_the_codes() -> None:
    """Every status of mlaunch.plan.errors' table is a row of the README's, and nothing else is."""
    from conftest import REPO

    from mlaunch.plan import errors

    readme = (REPO / "README.md").read_text()
    section = readme[readme.index("### Exit status") :]
    rows = re.findall(r"^\| ([0-9+N]+) \| (.+) \|$", section.split("\n\n", 2)[1], re.M)
    statuses = [status for status, _ in rows]
    codes = [errors.EXIT_OK, errors.EXIT_FAILURE, errors.EXIT_USAGE, errors.EXIT_INTERNAL]
    codes.append(errors.EXIT_OUTPUT)
    assert statuses == [*map(str, codes), f"{errors.SIGNAL_BASE}+N"]
    meaning = dict(rows)
    assert "130 for Ctrl-C" in meaning["128+N"]
    assert errors.exit_for_signal(signal.SIGINT) == 130 == errors.EXIT_INTERRUPTED
    # The same statuses in mlaunch --help's epilog.
    epilog = build_parser().epilog or ""
    for code in (*codes, 130):
        assert re.search(rf"\b{code}\b", epilog), (code, epilog)


def test_readme_leads_with_what_mlaunch_is_and_the_two_commands() -> None:
    """A new user reads what mlaunch is, the two commands, then how to use it: build details and
    measurements live in docs/ (usage began at line 73, after CI timings and the real-node build).
    """
    from conftest import REPO

    readme = (REPO / "README.md").read_text()
    lines = readme.splitlines()
    assert lines[2].startswith("mlaunch is "), lines[:4]
    block = readme.split("```sh\n", 1)[1].split("```", 1)[0]
    assert "./scripts/setup && .venv/bin/mlaunch launches/jtbot_sim.launch.py" in block
    assert "./scripts/check" in block
    assert lines.index("## Using it") < 40, lines.index("## Using it")
    assert not re.search(r"\b\d+ min \d+ s\b|\bload \d+ to \d+\b", readme), "measurements: docs/"
    linked = re.findall(r"\]\((docs/[\w.-]+\.md)\)", readme)
    assert "docs/setup.md" in linked
    for doc in linked:
        assert (REPO / doc).is_file(), doc


def test_viewer_on_a_busy_port_says_what_to_change() -> None:
    """MLAUNCH_VIEWER_PORT is read by the viewer itself: a busy port is its one-line error."""
    from mlaunch.standins.viewer import DisplayConfig, ViewerError, ViewerState, serve

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        with pytest.raises(ViewerError) as caught:
            serve(ViewerState(DisplayConfig()), port, lambda: 0.0)
    assert str(caught.value) == (
        f"cannot listen on 127.0.0.1:{port}: Address already in use; valid: a free port, or 0"
        " for any free port (mlaunch --viewer-port, or MLAUNCH_VIEWER_PORT)"
    )
