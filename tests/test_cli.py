"""End-to-end runs of the mlaunch command: output, logs, exit codes, signals, and clear errors."""

from __future__ import annotations

import os
import re
import signal
import sys
import textwrap
from pathlib import Path

import pytest
from procutil import (
    Running,
    clean_env,
    demo_package,
    mlaunch,
    pid_alive,
    run_mlaunch,
    wait_until,
)

PY = sys.executable


def launch_file(tmp_path: Path, body: str, name: str = "sys.launch.py") -> str:
    """A Python launch file whose generate_launch_description returns ``[body]``."""
    path = tmp_path / name
    path.write_text(
        textwrap.dedent(
            """
            import sys
            from launch import LaunchDescription
            from launch.actions import *
            from launch.substitutions import *
            from launch.conditions import *
            from launch.event_handlers import *
            PY = sys.executable

            def generate_launch_description():
                return LaunchDescription([
            """
        )
        + textwrap.indent(textwrap.dedent(body).strip(), " " * 8)
        + "\n    ])\n"
    )
    return str(path)


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))


def test_output_is_prefixed_decoded_and_flushed(tmp_path: Path, env: dict[str, str]) -> None:
    script = (
        "import sys; print('[talker] [INFO] hello [/foo]'); sys.stdout.flush();"
        " sys.stdout.buffer.write(b'bad \\xff byte\\n'); sys.stderr.write('to stderr\\n');"
        " sys.stdout.write('no newline at end')"
    )
    path = launch_file(
        tmp_path, f"ExecuteProcess(cmd=[PY, '-c', {script!r}], name='talker', output='screen'),"
    )
    done = run_mlaunch(path, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    out = done.stdout
    # Child text is data: brackets survive, invalid UTF-8 becomes U+FFFD, the partial line shows.
    assert "[talker-1] [talker] [INFO] hello [/foo]\n" in out
    assert "[talker-1] bad \ufffd byte\n" in out
    assert "[talker-1] to stderr\n" in out
    assert "[talker-1] no newline at end\n" in out
    assert re.search(r"\[INFO\] \[talker-1\]: process started with pid \[\d+\]", out)
    assert "[INFO] [talker-1]: process has finished cleanly" in out
    assert out.index("no newline at end") < out.index("finished cleanly")


def test_output_log_mode_hides_stdout_but_logs_it(tmp_path: Path, env: dict[str, str]) -> None:
    script = "import sys; print('quiet-out'); sys.stderr.write('loud-err\\n')"
    path = launch_file(tmp_path, f"ExecuteProcess(cmd=[PY, '-c', {script!r}], name='w'),")
    done = run_mlaunch(path, env=env)
    assert "quiet-out" not in done.stdout and "[w-1] loud-err" in done.stdout
    run_dir = Path(env["ROS_LOG_DIR"]) / "latest"
    assert run_dir.is_symlink()
    own = (run_dir / "w-1.log").read_text()
    assert "quiet-out\n" in own and "loud-err\n" in own
    launch_log = (run_dir / "launch.log").read_text()
    assert "process started with pid" in launch_log
    assert re.search(r"^\d+\.\d{7} \[w-1\] quiet-out$", launch_log, re.M)


def test_exit_codes(tmp_path: Path, env: dict[str, str]) -> None:
    failing = launch_file(
        tmp_path,
        """
        ExecuteProcess(cmd=[PY, '-c', 'import sys; sys.exit(3)'], name='core', on_exit=Shutdown()),
        ExecuteProcess(cmd=[PY, '-c', 'import time; time.sleep(60)'], name='other'),
        """,
    )
    done = run_mlaunch(failing, env=env)
    assert done.returncode == 1, done.stdout
    assert "process has died [pid" in done.stdout and "exited with status 3" in done.stdout
    assert "shutting down: required process core-1 exited with status 3" in done.stdout
    ok = launch_file(
        tmp_path,
        "ExecuteProcess(cmd=[PY, '-c', 'pass'], name='a', required=True),",
        name="ok.launch.py",
    )
    assert run_mlaunch(ok, env=env).returncode == 0
    # A non-required failure does not fail the launch (as ROS 2), but is reported.
    soft = launch_file(
        tmp_path,
        "ExecuteProcess(cmd=[PY, '-c', 'import os; os.abort()'], name='c'),",
        name="s.launch.py",
    )
    done = run_mlaunch(soft, env=env)
    assert done.returncode == 0 and "killed by SIGABRT" in done.stdout


def test_sigint_ladder_and_grandchildren(tmp_path: Path, env: dict[str, str]) -> None:
    stubborn = (
        "import signal, time, os; signal.signal(signal.SIGINT, signal.SIG_IGN);"
        " print('stubborn', os.getpid(), flush=True); time.sleep(60)"
    )
    family = (
        "import subprocess, time, sys; c = subprocess.Popen(['sleep', '60']);"
        " print('family', c.pid, flush=True); time.sleep(60)"
    )
    path = launch_file(
        tmp_path,
        f"""
        ExecuteProcess(cmd=[PY, '-c', {stubborn!r}], name='stubborn', output='screen',
                       sigterm_timeout='0.5', sigkill_timeout='0.5'),
        ExecuteProcess(cmd=[PY, '-c', {family!r}], name='family', output='screen'),
        """,
    )
    run = Running(mlaunch(path), env=env)
    try:
        stubborn_pid = int(run.wait_for(r"stubborn (\d+)").group(1))
        grandchild = int(run.wait_for(r"family (\d+)").group(1))
        run.signal(signal.SIGINT)
        code = run.finish(timeout=15)
    finally:
        run.kill()
    assert code == 130, run.text
    assert "escalating to SIGTERM" in run.text
    assert "[stubborn-1]: process stopped by SIGTERM" in run.text
    assert not pid_alive(stubborn_pid) and not pid_alive(grandchild)


def test_sigterm_to_mlaunch_stops_everything(tmp_path: Path, env: dict[str, str]) -> None:
    path = launch_file(
        tmp_path,
        "ExecuteProcess(cmd=[PY, '-c', 'import time,os; print(\"up\", os.getpid(), flush=True); time.sleep(60)'], output='screen'),",
    )
    run = Running(mlaunch(path), env=env)
    try:
        pid = int(run.wait_for(r"up (\d+)").group(1))
        run.signal(signal.SIGTERM)
        assert run.finish() == 143
    finally:
        run.kill()
    assert wait_until(lambda: not pid_alive(pid), 2.0)


def test_timer_and_event_handlers_run(tmp_path: Path, env: dict[str, str]) -> None:
    path = launch_file(
        tmp_path,
        """
        DeclareLaunchArgument('word', default_value='bye'),
        RegisterEventHandler(OnProcessExit(on_exit=[LogInfo(msg=['exited, ', LaunchConfiguration('word')])])),
        RegisterEventHandler(OnShutdown(on_shutdown=[LogInfo(msg='on shutdown')])),
        TimerAction(period=0.2, actions=[ExecuteProcess(cmd=[PY, '-c', 'print(42)'], name='late', output='screen')]),
        """,
    )
    done = run_mlaunch(path, "word:=ciao", env=env)
    assert done.returncode == 0
    out = done.stdout
    assert "[late-1] 42" in out and "exited, ciao" in out and "on shutdown" in out
    assert out.index("[late-1] 42") < out.index("exited, ciao")


def test_respawn_on_failure_with_retries(tmp_path: Path, env: dict[str, str]) -> None:
    path = launch_file(
        tmp_path,
        "ExecuteProcess(cmd=[PY, '-c', 'import sys; print(\"run\"); sys.exit(2)'], name='flaky',"
        " output='screen', respawn='on-failure', respawn_delay=0.05, respawn_max_retries=2),",
    )
    done = run_mlaunch(path, env=env)
    assert done.stdout.count("[flaky-1] run") == 3
    assert "restart 1/2" in done.stdout and "restart 2/2" in done.stdout
    assert "giving up after 2 restarts" in done.stdout


@pytest.mark.parametrize(
    ("body", "args", "message"),
    [
        (
            "DeclareLaunchArgument('robot'),",
            [],
            "Required launch argument 'robot' was not provided",
        ),
        (
            "DeclareLaunchArgument('m', default_value='a', choices=['a', 'b']),",
            ["m:=c"],
            "'c', which is not one of its choices: a, b",
        ),
        (
            "ExecuteProcess(cmd=['echo', LaunchConfiguration('nope')]),",
            [],
            "launch configuration 'nope' does not exist",
        ),
        (
            "ExecuteProcess(cmd=['no-such-program-xyz']),",
            [],
            "'no-such-program-xyz' not found on the PATH",
        ),
        (
            "LogInfo(msg=1/0),",
            [],
            "ZeroDivisionError in generate_launch_description(): division by zero",
        ),
    ],
)
def test_bad_input_is_one_clear_line(
    tmp_path: Path, env: dict[str, str], body: str, args: list[str], message: str
) -> None:
    path = launch_file(tmp_path, body)
    done = run_mlaunch(path, *args, env=env)
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert lines[0].startswith(f"mlaunch: error: {path}:") and message in lines[0]


def test_missing_file_syntax_error_and_malformed_argument(
    tmp_path: Path, env: dict[str, str]
) -> None:
    done = run_mlaunch(str(tmp_path / "nope.launch.py"), env=env)
    assert done.returncode == 2 and "does not exist" in done.stderr
    broken = tmp_path / "broken.launch.py"
    broken.write_text("def generate_launch_description()\n    return 1\n")
    done = run_mlaunch(str(broken), env=env)
    assert done.returncode == 2 and f"{broken}:1:" in done.stderr and "syntax error" in done.stderr
    ok = launch_file(tmp_path, "LogInfo(msg='x'),")
    done = run_mlaunch(ok, "novalue", env=env)
    assert done.returncode == 2 and "malformed launch argument 'novalue'" in done.stderr
    done = run_mlaunch(ok, "--debug", "m:=1", env=env)
    assert done.returncode == 0


def test_undeclared_argument_warns(tmp_path: Path, env: dict[str, str]) -> None:
    path = launch_file(tmp_path, "DeclareLaunchArgument('use_sim_time', default_value='false'),")
    done = run_mlaunch(path, "use_sim_tim:=true", env=env)
    assert done.returncode == 0
    assert (
        "argument 'use_sim_tim' is not declared by the launch file (did you mean 'use_sim_time'?)"
        in done.stdout
    )


def test_show_args_and_print(tmp_path: Path, env: dict[str, str]) -> None:
    path = launch_file(
        tmp_path,
        """
        DeclareLaunchArgument('world', default_value='empty.world', description='World file to load'),
        DeclareLaunchArgument('gui', default_value='true', choices=['true', 'false']),
        ExecuteProcess(cmd=[PY, '-c', 'pass', LaunchConfiguration('world')], name='sim',
                       respawn=True, respawn_delay=2.0, additional_env={'SIM_MODE': 'fast'}),
        """,
    )
    shown = run_mlaunch(path, "--show-args", env=env)
    assert shown.returncode == 0
    assert re.search(r"world\s+'empty.world'\s+World file to load", shown.stdout)
    assert "One of: ['true', 'false']" in shown.stdout
    printed = run_mlaunch(path, "--print", "world:=maze.world", env=env)
    assert printed.returncode == 0
    out = printed.stdout
    assert "sim-1" in out and "maze.world" in out and "SIM_MODE=fast" in out
    assert "respawn: always, delay 2 s, unlimited restarts" in out
    assert "SIGTERM after 5 s" in out
    # Nothing was started and no log directory was made.
    assert "process started" not in out
    assert not (Path(env["ROS_LOG_DIR"])).exists()


def test_plain_launch_never_imports_rclpy(tmp_path: Path, env: dict[str, str]) -> None:
    path = launch_file(tmp_path, "ExecuteProcess(cmd=[PY, '-c', 'pass']),")
    code = (
        "import sys; from mlaunch.cli import main; rc = main([sys.argv[1]]);"
        " heavy = sorted(m for m in ('rclpy', 'rich', 'asyncio', 'yaml') if m in sys.modules);"
        " print('IMPORTED', heavy); sys.exit(rc)"
    )
    done = __import__("subprocess").run(
        [PY, "-c", code, path], capture_output=True, text=True, env=env, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert "IMPORTED []" in done.stdout


HEAVY_AT_START = (
    "rclpy",
    "rich",
    "asyncio",
    "yaml",
    "dataclasses",
    "typing",
    "inspect",
    "psutil",
    "tempfile",
    # mlaunch ctl's socket opens on the loop's first turn, after the first children.
    "socket",
    "mlaunch.parts.control",
    "mlaunch.parts.control_socket",
    "json",  # only --print --format json (mlaunch.resolve.plan_json) and the ROS bridge need it
    # With re, fnmatch, urllib.parse, ipaddress (~3 ms): the ROS wheels' hook imports it in every
    # interpreter, which is why the check runs site without the hook, as the mlaunch command does.
    "pathlib",
)


def loaded_at_first_child(
    path: str,
    env: dict[str, str],
    options: tuple[str, ...] = (),
    modules: tuple[str, ...] = HEAVY_AT_START,
) -> list[str]:
    """The ``modules`` mlaunch has loaded once it has started the launch's first child.

    The child's own start is the moment checked: the supervisor's start() is wrapped, and the
    modules are looked for in mlaunch's sys.modules as soon as it returns.
    """
    code = (
        "import sys\n"
        # site as the mlaunch command runs it: without the ROS wheels' hook (mlaunch's own imports
        # are what is checked; a plain 'python' would have loaded pathlib for the hook).
        "sys.modules.setdefault('ros_wheels_bootstrapper', type(sys)('ros_wheels_bootstrapper'))\n"
        "import site\n"
        "site.main()\n"
        "import mlaunch.engine.supervisor as sup\n"
        "seen = []\n"
        "original = sup.Supervisor.start\n"
        "def start(self, *a, **k):\n"
        "    result = original(self, *a, **k)\n"
        f"    seen.extend(m for m in {modules!r} if m in sys.modules)\n"
        "    return result\n"
        "sup.Supervisor.start = start\n"
        "from mlaunch.cli import main\n"
        f"rc = main([sys.argv[1], '-q', *{options!r}])\n"
        "print('AT-FIRST-CHILD', sorted(set(seen)))\n"
        "sys.exit(rc)\n"
    )
    done = __import__("subprocess").run(
        [PY, "-S", "-c", code, path], capture_output=True, text=True, env=env, timeout=30
    )
    assert done.returncode == 0, done.stderr
    (line,) = [x for x in done.stdout.splitlines() if x.startswith("AT-FIRST-CHILD")]
    return list(eval(line.partition(" ")[2]))


def test_start_path_stays_light(tmp_path: Path, env: dict[str, str]) -> None:
    """The start-up budget (first child within 60 ms): what must not load before the first child.

    --show-args must not load the runtime at all.
    """
    path = launch_file(tmp_path, "ExecuteProcess(cmd=[PY, '-c', 'print(1)'], output='screen'),")
    assert loaded_at_first_child(path, env) == []
    show = (
        "import sys; from mlaunch.cli import main; rc = main([sys.argv[1], '--show-args']);"
        " runtime = ('mlaunch.engine.supervisor', 'mlaunch.engine.process', 'mlaunch.engine.output', 'subprocess', 'selectors');"
        " print('SHOW-ARGS', sorted(m for m in runtime if m in sys.modules)); sys.exit(rc)"
    )
    done = __import__("subprocess").run(
        [PY, "-c", show, path], capture_output=True, text=True, env=env, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert "SHOW-ARGS []" in done.stdout


def test_no_cache_loads_none_of_the_plan_cache(tmp_path: Path, env: dict[str, str]) -> None:
    """--no-cache and MLAUNCH_NO_CACHE=1 decide before the cache's code (and pickle) loads."""
    path = launch_file(tmp_path, "ExecuteProcess(cmd=[PY, '-c', 'print(1)'], output='screen'),")
    cache = ("mlaunch.app.plan_cache", "mlaunch.plan.inputs", "pickle")
    assert loaded_at_first_child(path, env, ("--no-cache",), cache) == []
    assert loaded_at_first_child(path, {**env, "MLAUNCH_NO_CACHE": "1"}, (), cache) == []
    assert loaded_at_first_child(path, env, (), cache) != []  # the check sees them otherwise


def test_node_start_path_stays_light(tmp_path: Path, env: dict[str, str]) -> None:
    """A launch of installed ROS nodes keeps the ExecuteProcess budget: the package lookup, names,
    namespaces, remaps, arguments and global parameters load nothing heavy before the first child.
    """
    prefix = demo_package(tmp_path)
    path = tmp_path / "nodes.launch.py"
    path.write_text(
        textwrap.dedent(
            """
            from launch import LaunchDescription
            from launch.actions import DeclareLaunchArgument
            from launch.substitutions import LaunchConfiguration
            from launch_ros.actions import Node, PushROSNamespace, SetParameter

            def generate_launch_description():
                return LaunchDescription([
                    DeclareLaunchArgument('ns', default_value='robot'),
                    PushROSNamespace(LaunchConfiguration('ns')),
                    SetParameter('use_sim_time', True),
                    Node(package='demo', executable='talker', name='talker', namespace='sub',
                         arguments=['--rate', '5'], remappings=[('chatter', 'out')],
                         output='screen'),
                ])
            """
        )
    )
    env = {**env, "AMENT_PREFIX_PATH": prefix}
    assert loaded_at_first_child(str(path), env) == []


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("one.launch.yaml", "launch:\n- executable: {cmd: echo hi, output: screen}\n"),
        ("one.launch.xml", '<launch><executable cmd="echo hi" output="screen"/></launch>\n'),
    ],
)
def test_frontends_stay_light(tmp_path: Path, env: dict[str, str], name: str, text: str) -> None:
    """YAML and XML launches keep the same budget: no dataclasses, typing or inspect either."""
    path = tmp_path / name
    path.write_text(text)
    code = (
        "import sys; from mlaunch.cli import main; rc = main([sys.argv[1], '-q']);"
        " heavy = ('rclpy', 'rich', 'dataclasses', 'typing', 'inspect', 'mlaunch.launch_ros.actions');"
        " print('LOADED', sorted(m for m in heavy if m in sys.modules)); sys.exit(rc)"
    )
    done = __import__("subprocess").run(
        [PY, "-c", code, str(path)], capture_output=True, text=True, env=env, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert "LOADED []" in done.stdout


def test_python_m_and_console_script_agree(tmp_path: Path, env: dict[str, str]) -> None:
    script = Path(sys.executable).parent / "mlaunch"
    if not script.exists():
        pytest.skip("the mlaunch console script is not installed in this environment")
    path = launch_file(tmp_path, "LogInfo(msg='same'),")
    done = __import__("subprocess").run(
        [str(script), path], capture_output=True, text=True, env=env, timeout=30
    )
    assert done.returncode == 0 and "[INFO] [launch.user]: same" in done.stdout
    assert os.path.exists(env["ROS_LOG_DIR"])


def test_package_and_file_form(tmp_path: Path, env: dict[str, str]) -> None:
    """`mlaunch PKG FILE args`: FILE found in the package's share folder, as ros2 launch does."""
    pkg = tmp_path / "src" / "demo_bringup"
    (pkg / "launch").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?><package format="3"><name>demo_bringup</name></package>\n'
    )
    (pkg / "launch" / "demo.launch.yaml").write_text(
        "launch:\n- arg: {name: who, default: nobody}\n- log: {message: hello $(var who)}\n"
    )
    done = run_mlaunch(
        "--package-path",
        str(tmp_path / "src"),
        "demo_bringup",
        "demo.launch.yaml",
        "who:=pkg",
        env=env,
    )
    assert done.returncode == 0, done.stderr
    assert "[INFO] [launch.user]: hello pkg" in done.stdout
    missing = run_mlaunch(
        "--package-path", str(tmp_path / "src"), "demo_bringup", "x.launch.py", env=env
    )
    assert missing.returncode == 2 and "was not found in the share directory" in missing.stderr


def test_on_process_io_callbacks(tmp_path: Path, env: dict[str, str]) -> None:
    """OnProcessIO callbacks get the bytes and may return actions; one that raises is reported."""
    path = launch_file(
        tmp_path,
        """
        ExecuteProcess(cmd=[PY, '-c', 'print("ready"); print("again")'], name='w', output='screen'),
        RegisterEventHandler(OnProcessIO(
            on_stdout=lambda event: [LogInfo(msg='saw ' + event.text.decode().split()[0])],
            handle_once=True)),
        """,
    )
    done = run_mlaunch(path, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("[launch.user]: saw ") == 1 and "saw ready" in done.stdout
    broken = launch_file(
        tmp_path,
        """
        ExecuteProcess(cmd=[PY, '-c', 'import time; print("x", flush=True); time.sleep(30)'], name='w'),
        RegisterEventHandler(OnProcessIO(on_stdout=lambda event: 1 / 0)),
        """,
        name="broken.launch.py",
    )
    done = run_mlaunch(broken, env=env)
    assert done.returncode == 2, done.stdout
    assert "OnProcessIO callback failed: ZeroDivisionError" in done.stdout
    assert f"{broken}:" in done.stdout
    # No traceback from mlaunch itself (the child's own KeyboardInterrupt lines are [w-1] ...).
    assert "Traceback" not in done.stderr
    assert not [line for line in done.stdout.splitlines() if line.startswith("Traceback")]


def test_python_including_xml_reads_no_entry_points(tmp_path: Path, env: dict[str, str]) -> None:
    """A Python launch file that includes XML through launch_xml's source (Autoware's do) pays
    for importlib.metadata (~20-40 ms) only if a tag outside the built-in tables needs it."""
    (tmp_path / "inner.launch.xml").write_text('<launch><log message="inner"/></launch>\n')
    outer = tmp_path / "outer.launch.py"
    inner = str(tmp_path / "inner.launch.xml")
    outer.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import IncludeLaunchDescription\n"
        "from launch_xml.launch_description_sources import XMLLaunchDescriptionSource\n\n\n"
        "def generate_launch_description():\n"
        f"    source = XMLLaunchDescriptionSource({inner!r})\n"
        "    return LaunchDescription([IncludeLaunchDescription(source)])\n"
    )
    code = (
        "import sys; from mlaunch.cli import main; rc = main([sys.argv[1], '--print']);"
        " print('LOADED', 'importlib.metadata' in sys.modules); sys.exit(rc)"
    )
    done = __import__("subprocess").run(
        [PY, "-c", code, str(outer)], capture_output=True, text=True, env=env, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert "inner" in done.stdout and "LOADED False" in done.stdout


SITE = Path(__import__("sysconfig").get_path("purelib"))
HOOKED = (SITE / "ros_wheels_bootstrapper.pth").exists()


def shell_env(env: dict[str, str]) -> dict[str, str]:
    """A user's shell: without what the ROS wheels' hook put into this process's environment."""
    from mlaunch.parts.ros1_environ import shell_environ

    return shell_environ(env)


@pytest.mark.skipif(not HOOKED, reason="no ROS wheels' .pth hook in this venv: nothing to skip")
def test_the_mlaunch_command_starts_python_once(tmp_path: Path, env: dict[str, str]) -> None:
    """The hook re-executes every interpreter of the venv (~20 ms): the mlaunch command that
    scripts/setup installs gives Python the finished environment at its first exec instead."""
    script = Path(sys.executable).parent / "mlaunch"
    path = launch_file(tmp_path, "LogInfo(msg='once'),")
    done = __import__("subprocess").run(
        [str(script), path, "--show-args"],
        capture_output=True,
        text=True,
        env={**shell_env(env), "PYTHONPROFILEIMPORTTIME": "1"},
        timeout=30,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    # Each interpreter writes this header once: two would be the hook's re-exec.
    assert done.stderr.count("import time: self [us] | cumulative | imported package") == 1
    # Nor is the hook imported (with its guard set it would import pathlib, for nothing).
    imported = {line.rpartition("|")[2].strip() for line in done.stderr.splitlines()}
    assert not {"ros_wheels_bootstrapper", "pathlib"} & imported


@pytest.mark.skipif(not HOOKED, reason="no ROS wheels' .pth hook in this venv")
def test_no_interpreter_of_the_venv_imports_the_hook_for_nothing(env: dict[str, str]) -> None:
    """Where its guard is set the hook does nothing but import pathlib (with re, fnmatch,
    urllib.parse, ipaddress): mlaunch_ros_hook.pth, which scripts/setup writes, keeps it out."""
    guarded = {**env, "_ROS_WHEELS_BOOTSTRAP_COMPLETE": "1"}
    code = "import sys; print(sorted(m for m in ('pathlib', 'ros_wheels_bootstrapper') if m in sys.modules and getattr(sys.modules[m], '__file__', None)))"
    done = __import__("subprocess").run(
        [PY, "-c", code], capture_output=True, text=True, env=guarded, timeout=30
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.mark.skipif(not HOOKED, reason="no ROS wheels' .pth hook in this venv")
def test_the_mlaunch_command_has_the_ros_libraries(tmp_path: Path, env: dict[str, str]) -> None:
    """What the hook gave before: rclpy loads in mlaunch itself (the launch file imports it here,
    as the bridge does lazily) and in the venv's Python programs it starts, which get the
    finished environment (every ros_*.libs folder on LD_LIBRARY_PATH, the guard) as before."""
    script = Path(sys.executable).parent / "mlaunch"
    child = (
        "import os, rclpy._rclpy_pybind11;"
        " print('CHILD', os.environ.get('_ROS_WHEELS_BOOTSTRAP_COMPLETE'),"
        " os.environ.get('LD_LIBRARY_PATH'))"
    )
    path = tmp_path / "rclpy.launch.py"
    path.write_text(
        textwrap.dedent(
            f"""
            import sys
            import rclpy._rclpy_pybind11
            from launch import LaunchDescription
            from launch.actions import ExecuteProcess

            def generate_launch_description():
                return LaunchDescription([
                    ExecuteProcess(cmd=[sys.executable, "-c", {child!r}], output="screen"),
                ])
            """
        )
    )
    done = __import__("subprocess").run(
        [str(script), str(path)], capture_output=True, text=True, env=shell_env(env), timeout=60
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    (line,) = [x for x in done.stdout.splitlines() if "CHILD" in x]
    guard, _, ld_path = line.partition("CHILD ")[2].partition(" ")
    assert guard == "1"
    entries = {os.path.realpath(e) for e in ld_path.split(os.pathsep)}
    wanted = {os.path.realpath(p) for p in SITE.glob("ros_*.libs")}
    assert wanted and wanted <= entries, (wanted - entries, ld_path)


@pytest.mark.skipif(not HOOKED, reason="no ROS wheels' .pth hook in this venv")
def test_the_mlaunch_command_runs_python_as_the_console_script(
    tmp_path: Path, env: dict[str, str]
) -> None:
    """No interpreter flags (multiprocessing passes sys.flags on to its spawned workers: -S left
    them without site-packages) and sys.path[0] the command's folder, as pip's script has it."""
    script = Path(sys.executable).parent / "mlaunch"
    path = launch_file(
        tmp_path,
        "LogInfo(msg=f'FLAGS {sys.flags.no_site}{int(sys.flags.safe_path)}{sys.flags.isolated} {sys.path[0]}'),",
    )
    done = __import__("subprocess").run(
        [str(script), path], capture_output=True, text=True, env=shell_env(env), timeout=30
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert f"FLAGS 000 {script.parent}" in done.stdout
