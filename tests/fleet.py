"""A simulated fleet for mlaunch's Ansible export: Ansible run against private sshd daemons on
127.0.0.1 (tests/sshd.py), the same computer reached as several hosts.

Shared by tests/test_export_ansible.py (what the plays do) and benchmarks/run.py's ``fleet``
group (how long a deploy takes): the launch split by machine, its inventory as exported with
what reaches the daemons added, and ``ansible-playbook`` run with the settings both use.
"""

from __future__ import annotations

import getpass
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import sshd

REPO = Path(__file__).resolve().parent.parent
PLAYBOOK = Path(sys.executable).parent / "ansible-playbook"
MLAUNCH = Path(sys.executable).parent / "mlaunch"
TALKER = REPO / "tests" / "nodes" / "talker.py"
# The hosts' Python for Ansible's modules: the system's, as on a robot (else this one)
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
# ssh's control sockets: a short path (108 bytes at most), one per process
CONTROL = f"/tmp/mlaunch-ansible-{os.getpid()}-%C"
# What the ROS graph of the hosts shares (launch_environment)
ROS_NAMES = ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "RMW_IMPLEMENTATION")


def missing() -> str | None:
    """Why a fleet cannot be simulated here, or None."""
    if not PLAYBOOK.exists():
        return "needs ansible-core in the venv (scripts/setup installs it)"
    if sshd.SSHD is None or shutil.which("ssh") is None:
        return "needs openssh-server and the ssh client"
    return None


# Two machines and a node given none: three shares, one talker each.
SPLIT = f"""\
import sys
from launch import LaunchDescription
from launch_ros.actions import Node
from mlaunch.actions import Machine

def talker(namespace, **machine):
    return Node(executable=sys.executable, arguments=[{str(TALKER)!r}], name="talker",
                namespace=namespace, exec_name="talker", **machine)

def generate_launch_description():
    return LaunchDescription([
        Machine(name="r1", address="r1"),
        Machine(name="r2", address="r2", user="{getpass.getuser()}"),
        talker("r1", machine="r1"),
        talker("r2", machine="r2"),
        talker("base"),
    ])
"""
# Each share's readiness waits for another share's node: all ready means one ROS graph.
SPLIT_PEERS = {"r1": "/r2/talker", "r2": "/base/talker", "local": "/r1/talker"}


def export(folder: Path, name: str, text: str, env: dict[str, str]) -> Path:
    """``text`` as FOLDER/launch/NAME.launch.py, exported to FOLDER/NAME (its programs are this
    venv's, hence --allow-standins)."""
    launch = folder / "launch" / f"{name}.launch.py"
    launch.parent.mkdir()
    launch.write_text(text)
    out = folder / name
    done = subprocess.run(
        [str(MLAUNCH), "export", str(launch), "--to", "ansible", str(out), "--allow-standins"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    if done.returncode != 0:
        raise RuntimeError(f"mlaunch export failed: {done.stderr}")
    return out


def strip_comments(text: str) -> str:
    """An exported YAML file's JSON body (its head is comments)."""
    return "\n".join(line for line in text.splitlines() if not line.startswith("#"))


def fleet_vars(root: Path, ros_env: dict[str, str]) -> dict[str, object]:
    """The inventory's variables for every host: this mlaunch, the hosts' folders under ROOT,
    one shared ROS domain, the system's Python for Ansible's modules."""
    return {
        "mlaunch": str(MLAUNCH),
        "install_root": str(root),
        "ready_timeout": 90,
        "launch_environment": {k: ros_env[k] for k in ROS_NAMES if k in ros_env},
        "ansible_python_interpreter": PYTHON,
    }


def split_inventory(
    out: Path, servers: list[sshd.Server], ros_env: dict[str, str], root: Path
) -> tuple[Path, dict[str, dict[str, object]]]:
    """The exported inventory of SPLIT with what reaches the daemons added ('local', the node
    given no machine, on the first daemon's computer too, in a folder of its own) and each
    host's readiness waiting for another's node; (its path, the hosts as exported)."""
    data = json.loads(strip_comments((out / "inventory.yml").read_text()))
    hosts: dict[str, dict[str, object]] = data["all"]["hosts"]
    exported = json.loads(json.dumps(hosts))
    hosts["local"]["ansible_host"] = "r1"
    for name, server in (("r1", servers[0]), ("r2", servers[1]), ("local", servers[0])):
        hosts[name]["ansible_ssh_common_args"] = f"-F {server.client_config}"
        hosts[name]["launch_arguments"] = {"mlaunch_expect_peer": f"node {SPLIT_PEERS[name]}"}
    data["all"]["vars"] = fleet_vars(root, ros_env)
    inv = out.parent / f"{out.name}-inventory.yml"
    inv.write_text(json.dumps(data, indent=2))
    return inv, exported


def play(
    out: Path, inv: Path, book: str, *extra: str, env: dict[str, str]
) -> subprocess.CompletedProcess[str]:
    """``ansible-playbook -i INV BOOK`` in the export's folder, with a home of its own."""
    home = out.parent / "ansible-home"
    settings = {
        **env,
        "ANSIBLE_HOME": str(home),
        "ANSIBLE_LOCAL_TEMP": str(home / "tmp"),
        "ANSIBLE_REMOTE_TEMP": str(home / "remote"),
        "ANSIBLE_NOCOLOR": "1",
        "ANSIBLE_RETRY_FILES_ENABLED": "0",
        "ANSIBLE_PIPELINING": "1",  # one connection per task, not five
        # Connections shared within a play; an idle master ends 2 s after the play's last use.
        "ANSIBLE_SSH_ARGS": f"-o ControlMaster=auto -o ControlPersist=2s -o ControlPath={CONTROL}",
        "ANSIBLE_SSH_TRANSFER_METHOD": "piped",  # the test's sshd has no sftp subsystem
    }
    return subprocess.run(
        [str(PLAYBOOK), "-i", str(inv), book, *extra],
        cwd=out,
        env=settings,
        capture_output=True,
        text=True,
        timeout=300,
        stdin=subprocess.DEVNULL,
    )
