"""MachineSpec: a machine as resolved for one run, and the run-wide table of declared machines."""

from __future__ import annotations

import itertools
import os

from mlaunch.plan.value import Value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# ROS 1's default for <machine timeout>: seconds to wait for the connection.
DEFAULT_TIMEOUT = 10.0


class MachineSpec(Value):
    """Where a process runs: ``address`` over ssh, or this computer when ``local``.

    ``user`` and ``ssh_port`` None leave the choice to the ssh configuration; ``env_loader`` is a
    program on the remote that sets the environment and runs its arguments (ROS 1's env-loader);
    ``timeout`` bounds the connection. ``local``: the address is this computer and the user is
    ours (ROS 1's rule), so processes start here without ssh.
    """

    _fields = ("name", "address", "user", "ssh_port", "env_loader", "timeout", "local", "origin")
    __slots__ = _fields

    def __init__(
        self,
        name: str,
        address: str,
        user: str | None = None,
        ssh_port: int | None = None,
        env_loader: str | None = None,
        timeout: float = DEFAULT_TIMEOUT,
        local: bool = False,
        origin: str = "",
    ) -> None:
        self.name = name
        self.address = address
        self.user = user
        self.ssh_port = ssh_port
        self.env_loader = env_loader
        self.timeout = timeout
        self.local = local
        self.origin = origin

    def __hash__(self) -> int:
        return hash(self._values())

    @property
    def destination(self) -> str:
        """``user@address:port`` as far as the launch file says (for messages)."""
        text = f"{self.user}@{self.address}" if self.user else self.address
        return f"{text}:{self.ssh_port}" if self.ssh_port else text

    def describe(self) -> str:
        if self.local:
            return f"{self.name} (this computer: {self.destination})"
        extra = f", env-loader {self.env_loader}" if self.env_loader else ""
        return f"{self.name} (ssh {self.destination}{extra})"


def is_local(address: str, user: str | None) -> bool:
    """ROS 1's rule: the address resolves to this computer and the user is ours (or not given).

    A name that does not resolve (an ssh ``Host`` alias) is remote: ssh resolves it.
    """
    import socket

    if user:
        import getpass

        if user != getpass.getuser():
            return False
    if address == "localhost":
        return True
    try:
        infos = socket.getaddrinfo(address, None, 0, 0, socket.IPPROTO_TCP)
    except (OSError, UnicodeError):
        return False
    ips = {str(info[4][0]) for info in infos}
    if any(ip.startswith("127.") or ip == "::1" for ip in ips):
        return True
    return bool(ips & local_addresses())


def local_addresses() -> set[str]:
    """This computer's addresses (its host name's, and what the kernel lists for IPv4/IPv6)."""
    import socket

    found: set[str] = set()
    try:
        found.update(str(i[4][0]) for i in socket.getaddrinfo(socket.gethostname(), None))
    except OSError:
        pass
    try:
        with open("/proc/net/if_inet6") as f:
            for line in f:
                raw = line.split()[0]
                found.add(socket.inet_ntop(socket.AF_INET6, bytes.fromhex(raw)))
    except OSError:
        pass
    found.update(_ipv4_addresses())
    return found


def _ipv4_addresses() -> set[str]:
    """IPv4 addresses of this computer's interfaces, from /proc/net/fib_trie's local entries."""
    out: set[str] = set()
    try:
        with open("/proc/net/fib_trie") as f:
            lines = f.read().splitlines()
    except OSError:
        return out
    for previous, line in itertools.pairwise(lines):
        if "/32 host LOCAL" in line:
            out.add(previous.split()[-1])
    return out


def declared(run_state: dict[str, Any]) -> dict[str, MachineSpec]:
    """The machines declared so far in this run, by name.

    Kept in the run's state (``LaunchContext.run_state``, which every resolution of a run shares:
    timers and handlers resolved later see the machines declared before them), as ROS 1's
    machine names are global to a launch.
    """
    table: dict[str, MachineSpec] = run_state.setdefault("machines", {})
    return table


def lookup(run_state: dict[str, Any], name: str, origin: str) -> MachineSpec:
    """The declared machine ``name``, or a located error naming the declared ones."""
    table = declared(run_state)
    spec = table.get(name)
    if spec is not None:
        return spec
    import difflib

    from mlaunch.plan.errors import LaunchFileError

    close = difflib.get_close_matches(name, list(table), n=1)
    if close:
        hint = f" (did you mean {close[0]!r}?)"
    elif table:
        hint = f"; declared: {', '.join(sorted(table))}"
    else:
        hint = "; no machine is declared (Machine(...), <machine>) before it"
    raise LaunchFileError(f"machine {name!r} is not declared{hint}", where=origin)


def remote_machines(run_state: dict[str, Any]) -> list[MachineSpec]:
    """The declared machines reached over ssh (empty for a launch without machines)."""
    table: dict[str, MachineSpec] = run_state.get("machines") or {}
    return [m for m in table.values() if not m.local]


def check_name(name: str) -> str | None:
    """Why ``name`` cannot name a machine, or None."""
    if not name or any(c.isspace() for c in name) or os.sep in name:
        return "a machine name is a non-empty word without spaces or '/'"
    return None


# --machine NAME: this run starts only machine NAME's share of the launch (mlaunch.app.options).
# ``LOCAL_SHARE`` names the share of the processes given no machine (the launching computer's).
LOCAL_SHARE = "local"


def machine_name(machine: MachineSpec | None) -> str:
    """The share a process of ``machine`` belongs to: the machine's name, else ``local``."""
    return LOCAL_SHARE if machine is None else machine.name


def placed(share: str | None, machine: MachineSpec | None) -> tuple[MachineSpec | None, bool]:
    """(the machine a process runs on as this run sees it, whether it runs elsewhere).

    ``share`` is the one this run starts (``--machine NAME``: the run state's
    ``plan.steps.SHARE``), None for the whole launch: then nothing changes. With it, a process
    of the chosen share runs here, without ssh (this run is on that machine: its machine is
    marked local), and a process of another share is elsewhere: this run does not start it.
    """
    if share is None:
        return machine, False
    if machine_name(machine) != share:
        return machine, True
    if machine is None or machine.local:
        return machine, False
    values = dict(zip(machine._fields, machine._values(), strict=True))
    values["local"] = True
    return MachineSpec(**values), False


def runs_elsewhere(share: str | None, machine: MachineSpec | None) -> bool:
    """Whether a process of ``machine`` belongs to another share than ``share``, this run's."""
    return share is not None and machine_name(machine) != share
