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
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

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


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _wait_listening(port: int, process: subprocess.Popen[bytes], log: Path) -> None:
    deadline = time.monotonic() + START_DEADLINE
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError(f"sshd exited at start: {log.read_text()}")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.2):
                return
        except OSError:
            time.sleep(0.02)
    raise RuntimeError(f"sshd did not listen on port {port} within {START_DEADLINE} s")


def start(root: Path) -> Server:
    """Generate keys and configs under ``root`` and start sshd on a free port."""
    host_pub = _keygen(root / "host_key")
    client_pub = _keygen(root / "client_key")
    (root / "authorized_keys").write_text(client_pub + "\n")
    port = _free_port()
    (root / "sshd_config").write_text(
        f"Port {port}\nListenAddress 127.0.0.1\nHostKey {root / 'host_key'}\n"
        f"AuthorizedKeysFile {root / 'authorized_keys'}\nPidFile {root / 'sshd.pid'}\n"
        "StrictModes no\nUsePAM no\nPasswordAuthentication no\nKbdInteractiveAuthentication no\n"
        "PermitRootLogin prohibit-password\nMaxSessions 64\nLogLevel ERROR\n"
    )
    (root / "known_hosts").write_text(f"[127.0.0.1]:{port} {host_pub}\n")
    (root / "ssh_config").write_text(
        f"Host {HOST_ALIAS}\n  HostName 127.0.0.1\n  Port {port}\n  User {getpass.getuser()}\n"
        f"  IdentityFile {root / 'client_key'}\n  IdentitiesOnly yes\n"
        f"  UserKnownHostsFile {root / 'known_hosts'}\n  StrictHostKeyChecking yes\n"
        "  LogLevel ERROR\n"
    )
    if os.geteuid() == 0:
        os.makedirs("/run/sshd", mode=0o755, exist_ok=True)  # sshd's privilege separation dir
    log = root / "sshd.log"
    with open(log, "wb") as err:
        process = subprocess.Popen(
            [str(SSHD), "-D", "-e", "-f", str(root / "sshd_config")],
            stdin=subprocess.DEVNULL,
            stdout=err,
            stderr=err,
            start_new_session=True,
        )
    try:
        _wait_listening(port, process, log)
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
