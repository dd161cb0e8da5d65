"""mlaunch export --to ansible, run by real Ansible against two "robots": two private sshd
daemons on 127.0.0.1 (the same computer on two ports, as a simulated fleet on one computer is).

Each host runs its part of the launch (its own robot:= argument) in a folder of its own, with a
shared ROS domain: each host's readiness waits for the other's node, so wait-ready passing on both
is the proof that they see each other. Then: a second deploy changes nothing, teardown leaves no
process and no folder, and a host whose launch dies at once is reported failed.
"""

from __future__ import annotations

import getpass
import json
import os
import re
import sys
import time
from pathlib import Path

import fleet
import pytest
import sshd
from fleet import PYTHON, SPLIT, TALKER, export, fleet_vars, play, split_inventory, strip_comments
from procutil import clean_env, run_mlaunch, wait_until

pytestmark = pytest.mark.skipif(fleet.missing() is not None, reason=fleet.missing() or "")

LAUNCH = f"""\
import sys
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

def generate_launch_description():
    die = LaunchConfiguration("die")
    return LaunchDescription([
        DeclareLaunchArgument("robot", default_value="r0"),
        DeclareLaunchArgument("die", default_value="false"),
        Node(executable=sys.executable, arguments=[{str(TALKER)!r}], name="talker",
             namespace=LaunchConfiguration("robot"), exec_name="talker",
             condition=UnlessCondition(die)),
        ExecuteProcess(cmd=[sys.executable, "-c", "exit(3)"], name="broken",
                       condition=IfCondition(die)),
    ])
"""


def recap(output: str) -> dict[str, dict[str, int]]:
    """PLAY RECAP's counts per host."""
    out = {}
    for host, counts in re.findall(r"^(r\d|local)\s+:\s+(ok=.*)$", output, re.M):
        out[host] = {k: int(v) for k, v in re.findall(r"(\w+)=(\d+)", counts)}
    return out


def talkers(root: Path) -> list[str]:
    """The test's talkers running on this computer, started in a host folder under ``root``
    (the test's own: the module's other test may run beside it): pid and command line."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            argv = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
            cwd = os.readlink(f"/proc/{pid}/cwd")  # (its folder may be removed: " (deleted)")
        except OSError:
            continue
        words = [w.decode(errors="replace") for w in argv if w]
        if str(TALKER) in words and cwd.startswith(f"{root}{os.sep}"):
            found.append(f"{pid} {' '.join(words)}")
    return found


@pytest.fixture(scope="module")
def robots(tmp_path_factory: pytest.TempPathFactory) -> object:
    """Two sshd daemons on 127.0.0.1, reached as the ssh aliases r1 and r2 (each server's own
    client configuration names it): the module's tests share them."""
    servers = []
    try:
        for name in ("r1", "r2"):
            servers.append(sshd.start(tmp_path_factory.mktemp(f"sshd-{name}"), alias=name))
        yield servers
    finally:
        for server in servers:
            sshd.stop(server)


def inventory(
    path: Path, servers: list[sshd.Server], ros_env: dict[str, str], hosts: dict[str, dict]
) -> Path:
    """r1 and r2 on their own servers; r3 on r2's (one computer, two inventory names)."""
    server_of = {"r1": servers[0], "r2": servers[1], "r3": servers[1]}
    data = {
        "all": {
            "hosts": {
                name: {
                    "ansible_host": "r1" if name == "r1" else "r2",
                    "ansible_ssh_common_args": f"-F {server_of[name].client_config}",
                    "launch_arguments": arguments,
                }
                for name, arguments in hosts.items()
            },
            "vars": fleet_vars(path.parent / "robots", ros_env),
        }
    }
    path.write_text(json.dumps(data, indent=2))
    return path


def test_an_export_of_programs_only_this_computer_has_is_refused_unless_allowed(
    tmp_path: Path,
) -> None:
    launch = tmp_path / "fleet.launch.py"
    launch.write_text(LAUNCH)
    refused = run_mlaunch("export", str(launch), "--to", "ansible", str(tmp_path / "out"),
                          env=clean_env())  # fmt: skip
    assert refused.returncode == 2, refused.stderr
    assert f"talker-1: runs {sys.executable}, inside " in refused.stderr, refused.stderr
    assert "--allow-standins" in refused.stderr
    assert not (tmp_path / "out").exists()  # nothing written
    done = run_mlaunch("export", str(launch), "--to", "ansible", str(tmp_path / "out"),
                       "--allow-standins", env=clean_env())  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "warning: talker-1: runs " in done.stderr
    assert "talker-1: runs " in (tmp_path / "out" / "README.md").read_text()


@pytest.mark.timeout(600)  # four playbook runs: two minutes on a loaded 2-core machine
def test_deploy_to_two_hosts_wait_ready_idempotent_teardown_and_a_failing_host(
    tmp_path: Path, ros_env: dict[str, str], robots: list[sshd.Server]
) -> None:
    out = export(tmp_path, "fleet", LAUNCH, clean_env())
    root = tmp_path / "robots" / "fleet"
    # Each robot's readiness includes the other's node: both pass only in one shared graph.
    # r3's launch dies at once.
    hosts = {
        "r1": {"robot": "r1", "mlaunch_expect_peer": "node /r2/talker"},
        "r2": {"robot": "r2", "mlaunch_expect_peer": "node /r1/talker"},
        "r3": {"robot": "r3", "die": "true"},
    }
    inv = inventory(tmp_path / "inventory.yml", robots, ros_env, hosts)

    checked = play(out, inv, "deploy.yml", "--check", env=clean_env())
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert all(c["changed"] > 0 for c in recap(checked.stdout).values()), checked.stdout
    assert not talkers(root) and not root.exists()  # check mode starts and writes nothing

    started = time.monotonic()
    deployed = play(out, inv, "deploy.yml", env=clean_env())
    took = time.monotonic() - started
    try:
        assert deployed.returncode == 2, deployed.stdout + deployed.stderr  # a host failed
        counts = recap(deployed.stdout)
        assert counts["r1"]["failed"] == counts["r2"]["failed"] == 0, deployed.stdout
        assert counts["r3"]["failed"] == 1, deployed.stdout
        assert re.search(r'"msg": "r1: ready: 3 checks met', deployed.stdout), deployed.stdout
        assert re.search(r'"msg": "r2: ready: 3 checks met', deployed.stdout), deployed.stdout
        assert "ended before it was ready" in deployed.stdout, deployed.stdout
        running = talkers(root)
        assert len(running) == 2, running
        assert any("__ns:=/r1" in t and "__node:=talker" in t for t in running), running
        assert any("__ns:=/r2" in t and "__node:=talker" in t for t in running), running
        for host in ("r1", "r2", "r3"):  # apart, by inventory name
            assert (root / host / "files" / "launch" / "fleet.launch.py").is_file()
            assert (root / host / "log").is_dir()
        print(f"deploy to three hosts (two ready, one failed): {took:.1f} s")

        again = play(out, inv, "deploy.yml", env=clean_env())
        counts = recap(again.stdout)
        assert counts["r1"]["changed"] == counts["r2"]["changed"] == 0, again.stdout
        assert counts["r1"]["failed"] == counts["r2"]["failed"] == 0, again.stdout
        assert counts["r3"]["failed"] == 1, again.stdout  # started again, dead again
        assert sorted(talkers(root)) == sorted(running)  # the same processes, untouched
    finally:
        down = play(out, inv, "teardown.yml", env=clean_env())
    assert down.returncode == 0, down.stdout + down.stderr
    assert wait_until(lambda: not talkers(root), 30), talkers(root)
    assert not root.exists(), list(root.rglob("*"))


def test_a_launch_with_machines_is_split_one_host_per_machine(tmp_path: Path) -> None:
    launch = tmp_path / "machines.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "from mlaunch.actions import Machine\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        "        Machine(name='gpu', address='gpu-box.local', user='ros', ssh_port=2200),\n"
        "        Machine(name='idle', address='idle-alias'),\n"
        "        ExecuteProcess(cmd=['sleep', '9'], name='here'),\n"
        "        ExecuteProcess(cmd=['sleep', '9'], name='there', machine='gpu'),\n"
        "    ])\n"
    )
    out = tmp_path / "out"
    done = run_mlaunch("export", str(launch), "--to", "ansible", str(out), env=clean_env())
    assert done.returncode == 0, done.stderr
    hosts = json.loads(strip_comments((out / "inventory.yml").read_text()))["all"]["hosts"]
    assert hosts == {
        "local": {"ansible_host": "192.0.2.10", "mlaunch_machine": "local"},
        "gpu": {
            "ansible_host": "gpu-box.local",
            "ansible_user": "ros",
            "ansible_port": 2200,
            "mlaunch_machine": "gpu",
        },
    }
    exported = json.loads(strip_comments((out / "export.yml").read_text()))
    assert exported["mlaunch_export"]["shares"] == ["local", "gpu"]
    assert "machine(s) idle start no process at launch" in done.stderr
    assert "split by machine" in (out / "README.md").read_text()
    assert (out / "files" / "launch" / "machines.launch.py").read_text() == launch.read_text()
    assert not (out / "files" / "launch" / "out").exists()  # the export is not copied into itself


def test_a_host_whose_share_is_not_the_launchs_fails_before_anything_is_copied(
    tmp_path: Path,
) -> None:
    out = export(tmp_path, "split", SPLIT, clean_env())
    inv = tmp_path / "inventory.yml"
    hosts = {
        "r1": {"ansible_connection": "local"},  # its share: by its name
        "robot9": {"ansible_connection": "local", "mlaunch_machine": "r9"},
    }
    variables = {"install_root": str(tmp_path / "robots"), "ansible_python_interpreter": PYTHON}
    inv.write_text(json.dumps({"all": {"hosts": hosts, "vars": variables}}))
    done = play(out, inv, "deploy.yml", "--check", env=clean_env())
    assert done.returncode == 2, done.stdout + done.stderr
    assert "robot9 runs share r9 (mlaunch_machine" in done.stdout, done.stdout
    assert "not one of the launch's: r1, r2, local" in done.stdout, done.stdout
    assert re.search(r"^robot9\s+:.*failed=1", done.stdout, re.M), done.stdout
    assert re.search(r"^r1\s+:.*failed=0", done.stdout, re.M), done.stdout
    assert not (tmp_path / "robots").exists()  # check mode, and robot9 stopped at once


@pytest.mark.timeout(400)  # two playbook runs: about a minute on a loaded 2-core machine
def test_a_launch_split_by_machine_runs_each_share_on_its_host(
    tmp_path: Path, ros_env: dict[str, str], robots: list[sshd.Server]
) -> None:
    out = export(tmp_path, "split", SPLIT, clean_env())
    root = tmp_path / "robots" / "split"
    inv, hosts = split_inventory(out, robots, ros_env, root.parent)
    # The example inventory: a host per machine with its address and user, and 'local'.
    assert {h: v.get("ansible_host") for h, v in hosts.items()} == {
        "r1": "r1", "r2": "r2", "local": "192.0.2.10"
    }  # fmt: skip
    assert hosts["r2"]["ansible_user"] == getpass.getuser()

    started = time.monotonic()
    deployed = play(out, inv, "deploy.yml", env=clean_env())
    took = time.monotonic() - started
    try:
        assert deployed.returncode == 0, deployed.stdout + deployed.stderr
        counts = recap(deployed.stdout)
        assert sorted(counts) == ["local", "r1", "r2"], deployed.stdout
        assert all(c["failed"] == 0 for c in counts.values()), deployed.stdout
        for host in ("r1", "r2", "local"):
            assert re.search(rf'"msg": "{host}: ready: ', deployed.stdout), deployed.stdout
        # Each host runs exactly its share: one talker each, started in its own folder by
        # an mlaunch that runs its --machine.
        running: dict[str, list[list[str]]] = {}
        for line in talkers(root):
            pid, *argv = line.split()
            host = os.path.basename(os.readlink(f"/proc/{pid}/cwd"))
            running.setdefault(host, []).append(argv)
        namespace = {"r1": "/r1", "r2": "/r2", "local": "/base"}
        assert sorted(running) == ["local", "r1", "r2"], running
        for host, argvs in running.items():
            assert argvs == [[sys.executable, str(TALKER), "--ros-args", "-r", "__node:=talker",
                              "-r", f"__ns:={namespace[host]}"]], (host, argvs)  # fmt: skip
            command = (root / host / "command").read_text()
            assert f" --machine {host}" in command, command
        print(f"deploy of a launch split over three hosts: {took:.1f} s")
    finally:
        down = play(out, inv, "teardown.yml", env=clean_env())
    assert down.returncode == 0, down.stdout + down.stderr
    assert wait_until(lambda: not talkers(root), 30), talkers(root)
    assert not root.exists(), list(root.rglob("*"))
