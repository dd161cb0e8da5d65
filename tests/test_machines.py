"""Machines: processes on another computer over ssh, against a private sshd on 127.0.0.1.

The "other computer" is the ``mltest`` ssh alias of the sshd fixture. Every test marks what it
starts with a token in the environment: ``MLTEST_LOCAL`` in mlaunch's own (inherited by the local
ssh clients and master) and ``MLTEST_REMOTE`` set by the launch file (inherited by everything on
the remote side), so "nothing left on either side" is a scan of /proc for that token.
"""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
import sshd as sshd_server
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_until
from sshd import HOST_ALIAS, Server

HEADER = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess, TimerAction
from mlaunch.actions import Machine, PushMachine

def generate_launch_description():
    return LaunchDescription([
        Machine(name="robot", address="{alias}"),
{entries}
    ])
"""


def write_launch(tmp_path: Path, token: str, entries: list[str]) -> Path:
    body = "\n".join(f"        {e}," for e in entries)
    text = HEADER.format(alias=HOST_ALIAS, entries=body).replace("TOKEN", token)
    path = tmp_path / "machines.launch.py"
    path.write_text(text)
    return path


def remote(cmd: str, **extra: object) -> str:
    """An ExecuteProcess on the robot, shell command ``cmd``, marked with the remote token."""
    options = "".join(f", {k}={v!r}" for k, v in extra.items())
    return (
        f"ExecuteProcess(cmd=['sh', '-c', {cmd!r}], machine='robot', output='screen',"
        f" additional_env={{'MLTEST_REMOTE': 'TOKEN'}}{options})"
    )


def marked(token: str) -> list[int]:
    """Processes (either side) whose environment carries the test's token."""
    found = []
    needle = f"={token}\0".encode()
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as f:
                env = f.read() + b"\0"
            with open(f"/proc/{entry}/stat") as f:
                state = f.read().split(") ", 1)[1][0]
        except OSError:
            continue
        if needle in env and state != "Z":
            found.append(int(entry))
    return found


def describe(pids: list[int]) -> str:
    out = []
    for pid in pids:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                text = f.read().replace(b"\0", b" ").decode()
            out.append(f"{pid}: {text[:120]}")
        except OSError:
            pass
    return "\n".join(out)


def assert_nothing_left(token: str, timeout: float = 15.0) -> None:
    if not wait_until(lambda: not marked(token), timeout):
        left = marked(token)
        raise AssertionError(f"left running:\n{describe(left)}")


@pytest.fixture(scope="module")
def sshd(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    yield from sshd_server.serve(tmp_path_factory)


@pytest.fixture
def token(request: pytest.FixtureRequest) -> str:
    return f"mltest-{os.getpid()}-{os.urandom(4).hex()}"


def env_for(server: Server, token: str) -> dict[str, str]:
    return clean_env(**server.env(), MLTEST_LOCAL=token, ROS_DOMAIN_ID="57")


def test_remote_output_exit_code_and_environment(sshd: Server, tmp_path: Path, token: str) -> None:
    path = write_launch(
        tmp_path,
        token,
        [
            "ExecuteProcess(cmd=['echo', 'here'], output='screen')",
            remote("echo remote domain=$ROS_DOMAIN_ID; echo oops >&2; printf partial; exit 3"),
        ],
    )
    done = run_mlaunch(str(path), env=env_for(sshd, token))
    out = done.stdout + done.stderr
    assert "[echo-1] here" in out
    assert "[sh-2] remote domain=57" in out
    assert "[sh-2] oops" in out
    assert "[sh-2] partial" in out
    assert "exited with status 3" in out
    assert "mlaunch-status" not in out and "\x1e" not in out
    assert done.returncode == 0, out
    assert_nothing_left(token)


def test_a_remote_signal_death_is_reported_as_a_signal(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    path = write_launch(tmp_path, token, [remote("kill -USR1 $$", required=True)])
    done = run_mlaunch(str(path), env=env_for(sshd, token))
    out = done.stdout + done.stderr
    assert "killed by SIGUSR1" in out, out
    assert done.returncode == 1, out


def test_remote_respawn_until_it_gives_up(sshd: Server, tmp_path: Path, token: str) -> None:
    path = write_launch(
        tmp_path,
        token,
        [remote("echo try; exit 1", respawn=True, respawn_delay=0.05, respawn_max_retries=2)],
    )
    done = run_mlaunch(str(path), env=env_for(sshd, token))
    out = done.stdout + done.stderr
    assert out.count("[sh-1] try") == 3, out
    assert "giving up after 2 restarts" in out, out
    assert_nothing_left(token)


def test_ctrl_c_climbs_the_ladder_on_the_remote(sshd: Server, tmp_path: Path, token: str) -> None:
    stubborn = "trap '' INT; echo up; while :; do sleep 0.05; done"
    path = write_launch(
        tmp_path, token, [remote(stubborn, sigterm_timeout=0.5), remote("echo up; exec sleep 100")]
    )
    run = Running(mlaunch(str(path)), env=env_for(sshd, token))
    try:
        run.wait_for(r"\[sh-1\] up", 20)
        run.wait_for(r"\[sh-2\] up", 20)
        run.signal(signal.SIGINT)
        assert run.finish(20) == 130, run.text
    finally:
        run.kill()
    assert "process stopped by SIGINT" in run.text  # sleep's group took SIGINT
    assert "escalating to SIGTERM" in run.text
    assert "process stopped by SIGTERM" in run.text
    assert_nothing_left(token)


def test_a_killed_connection_stops_the_remote_and_is_reported(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    path = write_launch(tmp_path, token, [remote("echo up; exec sleep 100")])
    run = Running(mlaunch(str(path)), env=env_for(sshd, token))
    try:
        run.wait_for(r"\[sh-1\] up", 20)
        masters = [p for p in marked(token) if b"ControlMaster=yes" in _cmdline(p)]
        assert len(masters) == 1, describe(marked(token))
        os.kill(masters[0], signal.SIGKILL)
        run.wait_for(r"no exit status came back from machine 'robot' .* the connection ended", 20)
        assert run.finish(20) == 0, run.text
    finally:
        run.kill()
    assert_nothing_left(token)


def test_kill_9_of_mlaunch_leaves_nothing_on_either_side(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    path = write_launch(
        tmp_path,
        token,
        [
            remote("echo up; sleep 100 & sleep 100"),
            remote("trap '' TERM INT; echo up; sleep 100", sigkill_timeout=1.0),
        ],
    )
    run = Running(mlaunch(str(path)), env=env_for(sshd, token))
    try:
        run.wait_for(r"\[sh-1\] up", 20)
        run.wait_for(r"\[sh-2\] up", 20)
        assert len(marked(token)) >= 6  # mlaunch, master, 2 clients, 2 agents and their shells
        os.kill(run.proc.pid, signal.SIGKILL)
        run.proc.wait(5)
    finally:
        run.kill()
    assert_nothing_left(token, timeout=20)


def test_batch_mode_makes_a_missing_key_a_clear_error(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    config = tmp_path / "ssh_config"
    original = sshd.client_config.read_text()
    config.write_text(original.replace("client_key", "no_such_key"))
    path = write_launch(tmp_path, token, [remote("echo never")])
    env = {**env_for(sshd, token), "MLAUNCH_SSH_CONFIG": str(config)}
    done = run_mlaunch(str(path), env=env, timeout=30)
    assert done.returncode == 2, done.stderr
    assert "cannot connect to machine 'robot'" in done.stderr
    assert "Permission denied" in done.stderr
    assert "BatchMode=yes" in done.stderr
    assert "never" not in done.stdout
    assert_nothing_left(token)


def test_print_shows_which_machine_runs_what(tmp_path: Path, token: str) -> None:
    path = write_launch(
        tmp_path, token, ["ExecuteProcess(cmd=['echo', 'here'])", remote("echo there")]
    )
    done = run_mlaunch(str(path), "--print", env=clean_env())
    assert done.returncode == 0, done.stderr
    blocks = done.stdout.split("\n\n")
    here = next(b for b in blocks if b.startswith("echo-1"))
    there = next(b for b in blocks if b.startswith("sh-2"))
    assert "machine:" not in here
    assert f"machine: robot (ssh {HOST_ALIAS})" in there


def _cmdline(pid: int) -> bytes:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read()
    except OSError:
        return b""


def test_the_agent_reaches_the_remote_through_env_loader(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    loader = tmp_path / "env.sh"
    loader.write_text('#!/bin/sh\nexport FROM_LOADER=yes\nexec "$@"\n')
    loader.chmod(0o755)
    path = tmp_path / "loader.launch.py"
    path.write_text(
        HEADER.replace("Machine(name=\"robot\", address=\"{alias}\")",
                       f"Machine(name='robot', address='{HOST_ALIAS}', env_loader='{loader}')")
        .format(alias=HOST_ALIAS, entries="        " + remote("echo loader=$FROM_LOADER") + ",")
        .replace("TOKEN", token)
    )  # fmt: skip
    done = run_mlaunch(str(path), env=env_for(sshd, token))
    assert "[sh-1] loader=yes" in done.stdout + done.stderr, done.stdout + done.stderr


def test_mlaunch_test_works_across_machines(sshd: Server, tmp_path: Path, token: str) -> None:
    path = write_launch(
        tmp_path,
        token,
        ["ExecuteProcess(cmd=['sleep', '30'])", remote("echo remote-ready; exec sleep 30")],
    )
    done = run_mlaunch(
        "test", str(path), "--hold", "0.2", "--expect-output", "sh-2:remote-ready",
        env=env_for(sshd, token), timeout=60,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert_nothing_left(token)


@pytest.fixture(scope="module")
def second_host(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    yield from sshd_server.serve_in_namespace(tmp_path_factory, "mltest2")


def test_two_hosts_and_this_computer_run_print_and_stop_cleanly(
    sshd: Server, second_host: Server, tmp_path: Path, token: str
) -> None:
    config = tmp_path / "ssh_config"
    config.write_text(sshd.client_config.read_text() + second_host.client_config.read_text())
    path = write_launch(
        tmp_path,
        token,
        [
            "Machine(name='far', address='mltest2')",
            "ExecuteProcess(cmd=['sh', '-c', 'echo here-up; exec sleep 30'], output='screen')",
            remote("echo robot-up $(hostname -I); exec sleep 30"),
            remote("echo far-up $(hostname -I); exec sleep 30").replace("'robot'", "'far'"),
        ],
    )
    env = {**env_for(sshd, token), "MLAUNCH_SSH_CONFIG": str(config)}
    run = Running(mlaunch(str(path)), env=env)
    try:
        run.wait_for(r"\[sh-1\] here-up", 20)
        run.wait_for(r"\[sh-2\] robot-up", 20)
        far = run.wait_for(r"\[sh-3\] far-up (.*)", 20)
        assert far.group(1).split()[0] == second_host_address(second_host)
        run.signal(signal.SIGINT)
        assert run.finish(20) == 130, run.text
    finally:
        run.kill()
    assert run.text.count("process stopped by SIGINT") == 3, run.text
    assert_nothing_left(token)


def second_host_address(server: Server) -> str:
    for line in server.client_config.read_text().splitlines():
        if line.strip().startswith("HostName"):
            return line.split()[1]
    raise AssertionError("no HostName in the second host's config")


def test_more_processes_than_an_sshd_allows_sessions_per_connection(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    # The fixture's sshd keeps OpenSSH's default MaxSessions 10: 12 processes need 2 connections.
    entries = [remote(f"echo up-{i}; exec sleep 30") for i in range(12)]
    path = write_launch(tmp_path, token, entries)
    run = Running(mlaunch(str(path)), env=env_for(sshd, token))
    try:
        for i in range(12):
            run.wait_for(rf"\] up-{i}$", 30)
        masters = [p for p in marked(token) if b"ControlMaster=yes" in _cmdline(p)]
        assert len(masters) == 2, describe(marked(token))
        run.signal(signal.SIGINT)
        assert run.finish(30) == 130, run.text
    finally:
        run.kill()
    assert "refused" not in run.text, run.text
    assert_nothing_left(token)


TALKER = """#!/bin/sh
echo "remote talker at $0"
for a in "$@"; do
  if [ "$prev" = "--params-file" ]; then echo "params at $a"; cat "$a"; fi
  prev=$a
done
"""


def robot_package(tmp_path: Path, program_text: str) -> tuple[Path, Path, Path]:
    """(prefix, program, env-loader): mlaunch_demo/talker installed in an ament prefix that only
    the env-loader (the robot's environment) names."""
    prefix = tmp_path / "robot-prefix"
    program = prefix / "lib" / "mlaunch_demo" / "talker"
    program.parent.mkdir(parents=True)
    program.write_text(program_text)
    program.chmod(0o755)
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "mlaunch_demo").write_text("")
    loader = tmp_path / "env.sh"
    loader.write_text(
        f'#!/bin/sh\nexport FROM_LOADER=yes AMENT_PREFIX_PATH="{prefix}"\nexec "$@"\n'
    )
    loader.chmod(0o755)
    return prefix, program, loader


def test_a_remote_node_is_found_there_and_gets_its_params_file(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    # The package exists only on the "remote" (its env-loader's AMENT_PREFIX_PATH), not here.
    _, program, loader = robot_package(tmp_path, TALKER)
    path = tmp_path / "node.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n"
        "from mlaunch.actions import Machine\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        f"        Machine(name='robot', address='{HOST_ALIAS}', env_loader='{loader}'),\n"
        "        Node(package='mlaunch_demo', executable='talker', name='talker',\n"
        "             machine='robot', output='screen', parameters=[{'rate': 5}],\n"
        f"             additional_env={{'MLTEST_REMOTE': '{token}'}}),\n"
        "    ])\n"
    )
    env = env_for(sshd, token)
    env.pop("AMENT_PREFIX_PATH", None)
    done = run_mlaunch(str(path), env=env)
    out = done.stdout + done.stderr
    assert f"remote talker at {program}" in out, out
    assert "rate: 5" in out, out
    params = next(
        line.split("params at ", 1)[1] for line in out.splitlines() if "params at" in line
    )
    assert not params.startswith(str(tmp_path))  # a copy in the remote's own temp dir
    assert wait_until(lambda: not os.path.exists(os.path.dirname(params)), 10), params
    assert_nothing_left(token)


def test_cwd_is_a_directory_of_the_remote(sshd: Server, tmp_path: Path, token: str) -> None:
    # Not checked here (it is the remote's): only the remote's answer says whether it exists.
    path = write_launch(
        tmp_path,
        token,
        [remote("echo in $(pwd)", cwd="/proc"), remote("echo never", cwd="/no/such/dir")],
    )
    done = run_mlaunch(str(path), env=env_for(sshd, token))
    out = done.stdout + done.stderr
    assert "[sh-1] in /proc" in out, out
    assert "failed to start 'sh' on this computer" in out, out
    assert "exited with status 127" in out, out


SAYER = """#!/bin/sh
echo "program $0"
echo "loader=$FROM_LOADER launch=$SET_BY_LAUNCH domain=$ROS_DOMAIN_ID"
for a in "$@"; do
  if [ "$prev" = "--params-file" ]; then echo "arg <params>"; sed 's/^/params: /' "$a"
  else echo "arg $a"; fi
  prev=$a
done
"""


def test_a_machines_share_run_there_gives_its_node_what_ssh_gives_it(
    sshd: Server, tmp_path: Path, token: str
) -> None:
    # mlaunch FILE --machine robot, run on the robot, starts the robot's node as the launcher's
    # ssh agent does: the same program, arguments, parameters and environment.
    prefix, program, loader = robot_package(tmp_path, SAYER)
    path = tmp_path / "node.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import SetEnvironmentVariable\n"
        "from launch_ros.actions import Node\n"
        "from mlaunch.actions import Machine\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        f"        Machine(name='robot', address='{HOST_ALIAS}', env_loader='{loader}'),\n"
        "        SetEnvironmentVariable('SET_BY_LAUNCH', 'set'),\n"
        "        Node(package='mlaunch_demo', executable='talker', name='talker',\n"
        "             namespace='r', machine='robot', output='screen',\n"
        "             parameters=[{'rate': 5, 'frame': 'base'}], remappings=[('a', 'b')],\n"
        f"             arguments=['x y'], additional_env={{'MLTEST_REMOTE': '{token}'}}),\n"
        "    ])\n"
    )

    def said(done: subprocess.CompletedProcess[str]) -> list[str]:
        out = done.stdout + done.stderr
        lines = out.splitlines()
        return [line.split("] ", 1)[1] for line in lines if line.startswith("[talker-1] ")]

    env = env_for(sshd, token)
    env.pop("AMENT_PREFIX_PATH", None)
    over_ssh = said(run_mlaunch(str(path), env=env))  # the package is the robot's (env-loader)
    here = said(run_mlaunch(str(path), "--machine", "robot",
                            env={**env, "AMENT_PREFIX_PATH": str(prefix)}))  # fmt: skip
    assert over_ssh[0] == f"program {program}", over_ssh
    assert "loader=yes launch=set domain=57" in over_ssh, over_ssh
    assert "params:     rate: 5" in over_ssh and "arg x y" in over_ssh, over_ssh
    assert here == over_ssh
    assert_nothing_left(token)
