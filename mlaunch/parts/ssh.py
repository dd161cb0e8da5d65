"""One multiplexed OpenSSH connection per machine: the system's ``ssh``, never a transport of ours.

The first process for a machine opens a master connection (``ControlMaster``) with its control
socket in a private directory; every remote process is then an ``ssh`` client multiplexed over
it, so starting one costs a round trip, not a login. ``BatchMode`` makes a missing key or an
unknown host key an immediate error instead of a password prompt nobody sees. The user's ssh
configuration applies as usual; ``MLAUNCH_SSH_CONFIG=FILE`` is passed as ``ssh -F FILE`` (tests,
special setups). ``ServerAliveInterval`` bounds how long a dead network goes unnoticed.

The master is mlaunch's child, in a session of its own, carrying the run's marker in its
environment: if mlaunch is killed, the guard ends it like any process of the run. It is closed
(``ssh -O exit``) when the last process that uses it has ended, so nothing of the run is left
for the supervisor's sweep of stray descendants to find.
"""

from __future__ import annotations

import os
import subprocess
import time
from collections.abc import Mapping

from mlaunch.plan.machine import MachineSpec

# Seconds between keep-alives, and how many may go unanswered before ssh gives up.
ALIVE_INTERVAL = 3
ALIVE_COUNT = 3
# How often the connection wait looks for the control socket.
SOCKET_POLL = 0.01


class ConnectError(OSError):
    """A machine cannot be reached: the message says which one, why, and what to do."""


def base_options(environ: Mapping[str, str]) -> list[str]:
    """The ssh options of every command mlaunch runs (master, clients, ``-O``)."""
    options = ["-o", "BatchMode=yes"]
    config = environ.get("MLAUNCH_SSH_CONFIG")
    if config:
        options = ["-F", config, *options]
    return options


def destination_options(machine: MachineSpec) -> list[str]:
    options = []
    if machine.user:
        options += ["-l", machine.user]
    if machine.ssh_port:
        options += ["-p", str(machine.ssh_port)]
    return options


class Connection:
    """The master connection to one machine, opened on first use and closed with its last user."""

    def __init__(
        self,
        machine: MachineSpec,
        socket_path: str,
        environ: Mapping[str, str],
        extra_env: Mapping[str, str] | None = None,
    ) -> None:
        self.machine = machine
        self.socket_path = socket_path
        self.environ = dict(environ)
        self.extra_env = dict(extra_env or {})
        self.master: subprocess.Popen[bytes] | None = None
        self.users = 0

    def ssh_command(self, remote_command: str) -> list[str]:
        """An ssh client argv that runs ``remote_command`` over the master (no tty)."""
        return [
            "ssh",
            *base_options(self.environ),
            "-o",
            f"ControlPath={self.socket_path}",
            "-o",
            "ControlMaster=no",
            *destination_options(self.machine),
            "-T",
            self.machine.address,
            "--",
            remote_command,
        ]

    @property
    def open(self) -> bool:
        return (
            self.master is not None
            and self.master.poll() is None
            and os.path.exists(self.socket_path)
        )

    def acquire(self) -> None:
        """Count one more user, connecting first when needed (raises ConnectError)."""
        if not self.open:
            self.connect()
        self.users += 1

    def release(self) -> None:
        """One user fewer; the last one closes the master."""
        self.users = max(0, self.users - 1)
        if self.users == 0:
            self.close()

    def connect(self) -> None:
        """Open the master and wait (up to the machine's timeout) until its socket listens."""
        self.close()
        machine = self.machine
        errors = self.socket_path + ".err"
        argv = [
            "ssh",
            *base_options(self.environ),
            "-o",
            f"ControlPath={self.socket_path}",
            "-o",
            "ControlMaster=yes",
            "-o",
            "ControlPersist=no",
            "-o",
            f"ConnectTimeout={max(1, round(machine.timeout))}",
            "-o",
            f"ServerAliveInterval={ALIVE_INTERVAL}",
            "-o",
            f"ServerAliveCountMax={ALIVE_COUNT}",
            *destination_options(machine),
            "-N",
            "-T",
            machine.address,
        ]
        with open(errors, "wb") as err:
            try:
                self.master = subprocess.Popen(
                    argv,
                    stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL,
                    stderr=err,
                    env={**self.environ, **self.extra_env},
                    start_new_session=True,
                    close_fds=True,
                )
            except OSError as e:
                raise ConnectError(
                    f"cannot run ssh for machine {machine.name!r}: {e.strerror}"
                    " (install the OpenSSH client: apt-get install openssh-client)"
                ) from e
        deadline = time.monotonic() + machine.timeout + 1.0
        while not os.path.exists(self.socket_path):
            if self.master.poll() is not None or time.monotonic() > deadline:
                self._fail(errors)
            time.sleep(SOCKET_POLL)  # ssh says nothing when its socket is ready

    def _fail(self, errors: str) -> None:
        self.close()
        try:
            with open(errors, encoding="utf-8", errors="replace") as f:
                said = " ".join(line.strip() for line in f if line.strip())
        except OSError:
            said = ""
        machine = self.machine
        said = said or f"no answer within {machine.timeout:g} s"
        hint = ""
        if "Permission denied" in said or "Host key verification failed" in said:
            hint = (
                "; mlaunch runs ssh with BatchMode=yes (no password prompts): install a key"
                " (ssh-copy-id) and accept the host key (ssh once by hand) for this user"
            )
        raise ConnectError(
            f"cannot connect to machine {machine.name!r} ({machine.destination}): {said}{hint}"
        )

    def close(self) -> None:
        """Close the master (if any) and wait for it, so that nothing of it outlives the run."""
        master, self.master = self.master, None
        if master is None:
            return
        if master.poll() is None:
            try:
                subprocess.run(
                    ["ssh", *base_options(self.environ), "-o", f"ControlPath={self.socket_path}",
                     "-O", "exit", self.machine.address],
                    stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                    timeout=2.0,
                    check=False,
                )  # fmt: skip
            except (OSError, subprocess.TimeoutExpired):
                pass
            try:
                master.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                master.kill()
                master.wait()
        try:
            os.unlink(self.socket_path)
        except OSError:
            pass
