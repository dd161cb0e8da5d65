"""A private OpenSSH server on 127.0.0.1 for the machines tests, and the client config to reach it.

Everything lives in a temp dir: a host key and a client key generated for the test, an
``authorized_keys``, the server's config, and a client config (``MLAUNCH_SSH_CONFIG``) where the
``Host`` alias ``mltest`` is this server (an alias, so mlaunch treats it as another computer, as
it would a robot). Skips clearly when Debian's openssh-server is not installed.
"""

from __future__ import annotations

import getpass
import os
import shutil
import socket
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from ports import free_port
from procutil import wait_until

SSHD = shutil.which("sshd") or ("/usr/sbin/sshd" if os.path.exists("/usr/sbin/sshd") else None)
HOST_ALIAS = "mltest"
START_DEADLINE = 10.0


class Server:
    """A running sshd and what a client needs to use it."""

    def __init__(self, root: Path, port: int, process: subprocess.Popen[bytes]) -> None:
        self.root = root
        self.port = port
        self.process = process
        self.client_config = root / "ssh_config"
        self.log = root / "sshd.log"

    def env(self) -> dict[str, str]:
        return {**os.environ, "MLAUNCH_SSH_CONFIG": str(self.client_config)}

    def ssh(self, command: str, timeout: float = 10.0) -> subprocess.CompletedProcess[str]:
        """Run ``command`` on the server directly (not through mlaunch), for checks."""
        return subprocess.run(
            ["ssh", "-F", str(self.client_config), "-o", "BatchMode=yes", HOST_ALIAS, command],
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
        )


def _keygen(path: Path) -> str:
    subprocess.run(
        ["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", str(path)],
        check=True,
        stdin=subprocess.DEVNULL,
    )
    return path.with_suffix(".pub").read_text().strip()


def _wait_listening(address: str, port: int, process: subprocess.Popen[bytes], log: Path) -> None:
    def listening() -> bool:
        if process.poll() is not None:
            raise RuntimeError(f"sshd exited at start: {log.read_text()}")
        try:
            with socket.create_connection((address, port), timeout=0.2):
                return True
        except OSError:
            return False

    if not wait_until(listening, START_DEADLINE):
        raise RuntimeError(f"sshd did not listen on port {port} within {START_DEADLINE} s")


def start(
    root: Path,
    *,
    address: str = "127.0.0.1",
    alias: str = HOST_ALIAS,
    wrap: tuple[str, ...] = (),
) -> Server:
    """Generate keys and configs under ``root`` and start sshd on a free port of ``address``.

    ``wrap`` runs sshd through a command (``ip netns exec NS``: a second "host").
    """
    host_pub = _keygen(root / "host_key")
    client_pub = _keygen(root / "client_key")
    (root / "authorized_keys").write_text(client_pub + "\n")
    port = free_port()
    (root / "sshd_config").write_text(
        f"Port {port}\nListenAddress {address}\nHostKey {root / 'host_key'}\n"
        f"AuthorizedKeysFile {root / 'authorized_keys'}\nPidFile {root / 'sshd.pid'}\n"
        "StrictModes no\nUsePAM no\nPasswordAuthentication no\nKbdInteractiveAuthentication no\n"
        "PermitRootLogin prohibit-password\nLogLevel ERROR\n"  # MaxSessions: the default 10
    )
    (root / "known_hosts").write_text(f"[{address}]:{port} {host_pub}\n")
    (root / "ssh_config").write_text(
        f"Host {alias}\n  HostName {address}\n  Port {port}\n  User {getpass.getuser()}\n"
        f"  IdentityFile {root / 'client_key'}\n  IdentitiesOnly yes\n"
        f"  UserKnownHostsFile {root / 'known_hosts'}\n  StrictHostKeyChecking yes\n"
        "  LogLevel ERROR\n"
    )
    if os.geteuid() == 0:
        os.makedirs("/run/sshd", mode=0o755, exist_ok=True)  # sshd's privilege separation dir
    log = root / "sshd.log"
    with open(log, "wb") as err:
        process = subprocess.Popen(
            [*wrap, str(SSHD), "-D", "-e", "-f", str(root / "sshd_config")],
            stdin=subprocess.DEVNULL,
            stdout=err,
            stderr=err,
            start_new_session=True,
        )
    try:
        _wait_listening(address, port, process, log)
    except BaseException:
        process.kill()
        process.wait()
        raise
    return Server(root, port, process)


def stop(server: Server) -> None:
    # sshd's session processes run in their own sessions: end them with their parent's group
    # only after the test has checked that mlaunch left nothing there.
    server.process.terminate()
    try:
        server.process.wait(timeout=5)
    except subprocess.TimeoutExpired:
        server.process.kill()
        server.process.wait()


def serve(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """The body of a module-scoped fixture: a server for the module's tests, or a clear skip."""
    if SSHD is None or shutil.which("ssh") is None or shutil.which("ssh-keygen") is None:
        pytest.skip("sshd/ssh not installed: apt-get install openssh-server openssh-client")
    server = start(tmp_path_factory.mktemp("sshd"))
    try:
        yield server
    finally:
        stop(server)


class Namespace:
    """A network namespace joined to this one by a veth pair: a second "host" on one machine."""

    def __init__(self) -> None:
        tag = f"{os.getpid() % 100000}{os.urandom(1).hex()}"
        self.name = f"mlaunch-{tag}"
        self.veth = f"mlv{tag}"[:13]
        subnet = 4 * (os.getpid() % 60)
        third = int(os.urandom(1).hex(), 16)
        self.host_ip = f"10.231.{third}.{subnet + 1}"
        self.ns_ip = f"10.231.{third}.{subnet + 2}"

    def create(self) -> None:
        ns, host, inner = self.name, self.veth + "a", self.veth + "b"
        for command in (
            ["ip", "netns", "add", ns],
            ["ip", "link", "add", host, "type", "veth", "peer", "name", inner],
            ["ip", "link", "set", inner, "netns", ns],
            ["ip", "addr", "add", f"{self.host_ip}/30", "dev", host],
            ["ip", "link", "set", host, "up"],
            ["ip", "netns", "exec", ns, "ip", "addr", "add", f"{self.ns_ip}/30", "dev", inner],
            ["ip", "netns", "exec", ns, "ip", "link", "set", inner, "up"],
            ["ip", "netns", "exec", ns, "ip", "link", "set", "lo", "up"],
        ):
            subprocess.run(command, check=True, capture_output=True, timeout=10)

    def delete(self) -> None:
        subprocess.run(["ip", "link", "del", self.veth + "a"], capture_output=True, timeout=10)
        subprocess.run(["ip", "netns", "del", self.name], capture_output=True, timeout=10)


def serve_in_namespace(tmp_path_factory: pytest.TempPathFactory, alias: str) -> Iterator[Server]:
    """A module fixture's body: sshd in a network namespace of its own, or a clear skip."""
    if SSHD is None or shutil.which("ssh") is None or shutil.which("ip") is None:
        pytest.skip("sshd, ssh or ip not installed: apt-get install openssh-server iproute2")
    namespace = Namespace()
    try:
        namespace.create()
    except (OSError, subprocess.CalledProcessError) as e:
        namespace.delete()
        detail = getattr(e, "stderr", b"") or b""
        pytest.skip(f"cannot make a network namespace here (needs root): {detail.decode().strip()}")
    try:
        server = start(
            tmp_path_factory.mktemp("sshd-ns"),
            address=namespace.ns_ip,
            alias=alias,
            wrap=("ip", "netns", "exec", namespace.name),
        )
        try:
            yield server
        finally:
            stop(server)
    finally:
        namespace.delete()
