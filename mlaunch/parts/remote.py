"""Remote processes: the supervisor's process seam for a spec whose machine is another computer.

A ``RemoteProcess`` is a ``Process`` whose local child is an ``ssh`` client multiplexed over the
machine's connection, running the agent (mlaunch.parts.agent) on the remote. To the
supervisor it is a process like any other:

- its pipes carry the remote process's stdout and stderr, so the printer, the log files and
  OnProcessIO see the usual labels and lines;
- ``signal_group`` writes the signal number on the agent's stdin, and the agent signals the
  remote process group: the stop ladder reaches the remote group;
- the agent's status record (last line on stderr) becomes ``returncode``, ``core_dumped``, peak
  memory and CPU time, so respawn, ``required`` and exit handlers work as for local processes;
- a client that ends without a status lost its connection: that is said on stderr with the
  label, and the exit is a failure (ssh's 255), so ``respawn`` reconnects;
- the local ssh client is in a session of its own like any child, so the guard ends it if mlaunch
  is killed; its end closes the remote agent's stdin, and the agent ends the remote group.

``Spawner`` makes the processes (local ones stay plain ``Process``) and owns the connections.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import shlex
import subprocess
import time
from collections.abc import Callable, Mapping

from mlaunch.engine.process import Process
from mlaunch.parts import agent as agent_module
from mlaunch.parts.ssh import ConnectError, Connection
from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.machine import MachineSpec

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.plan.steps import ProcessSpec

# The local environment a remote process gets: the ROS network settings, not this computer's
# install paths (the remote has its own, from its login or env-loader).
FORWARDED_PREFIXES = ("ROS_", "RMW_", "RCUTILS_", "FASTRTPS_", "CYCLONEDDS_", "ZENOH_")
NOT_FORWARDED = frozenset(
    {"ROS_DISTRO", "ROS_VERSION", "ROS_PYTHON_VERSION", "ROS_HOME", "ROS_LOG_DIR",
     "ROS_PACKAGE_PATH", "ROS_ETC_DIR", "ROS_ROOT", "ROS_MASTER_URI"}
)  # fmt: skip
# OpenSSH servers allow 10 sessions per connection (sshd_config MaxSessions, default 10): a
# machine running more processes than that gets another connection for each ten.
SESSIONS_PER_CONNECTION = 10
# The agent waits at most this long between SIGTERM and SIGKILL when mlaunch is gone.
MAX_GRACE = 10.0
LOST = (
    "mlaunch: no exit status came back from machine {name!r} ({where}): the connection ended"
    " before the process did (the agent there stops its group), or the agent could not start"
    " (is python3 on that machine's PATH?)\n"
)


def remote_environment(spec: ProcessSpec) -> dict[str, str | None]:
    """What the agent sets on top of the remote login environment (None: unset it)."""
    env: dict[str, str | None] = {
        k: v
        for k, v in spec.env.items()
        if k.startswith(FORWARDED_PREFIXES) and k not in NOT_FORWARDED
    }
    env.update(spec.env_changes)
    return env


def params_files(spec: ProcessSpec) -> list[tuple[int, str, str]]:
    """(argv index, file name, base64 content) of every ``--params-file`` that exists here."""
    files: list[tuple[int, str, str]] = []
    for i in range(1, len(spec.argv)):
        if spec.argv[i - 1] != "--params-file" or not os.path.isfile(spec.argv[i]):
            continue
        with open(spec.argv[i], "rb") as f:
            data = base64.b64encode(f.read()).decode("ascii")
        files.append((i, f"{len(files)}-{os.path.basename(spec.argv[i])}", data))
    return files


def agent_config(spec: ProcessSpec) -> dict[str, object]:
    """Everything the agent needs to start ``spec`` on the remote."""
    config: dict[str, object] = {
        "argv": list(spec.argv),
        "env": remote_environment(spec),
        "cwd": spec.cwd,
        "shell": spec.shell,
        "grace": min(MAX_GRACE, spec.sigkill_timeout),
        "files": params_files(spec),
    }
    node = spec.node
    if node is not None and node.package and not spec.shell:
        for i, item in enumerate(spec.argv):
            if item == f"{node.package}/{node.executable}" or (
                os.path.basename(item) == node.executable
            ):
                config["node"] = [i, node.package, node.executable]
                break
    return config


def agent_program(spec: ProcessSpec) -> bytes:
    """The length-prefixed program the bootstrap reads from stdin: the agent plus its config."""
    with open(agent_module.__file__, "rb") as f:
        source = f.read()
    config = json.dumps(agent_config(spec))
    program = source + b"\nCONFIG = " + repr(config).encode() + b"\n"
    return str(len(program)).encode() + b"\n" + program


def remote_command(machine: MachineSpec) -> str:
    """The command line the remote shell runs: the bootstrap, through env-loader if any."""
    words = ["python3", "-c", agent_module.BOOTSTRAP]
    if machine.env_loader:
        words.insert(0, machine.env_loader)
    return "exec " + shlex.join(words)


class RemoteProcess(Process):
    """A process on another computer, seen through its local ssh client (see the module doc)."""

    __slots__ = ("connection", "control", "lost", "remote_status")

    def __init__(
        self, spec: ProcessSpec, index: int, restarts: int = 0, *, connection: Connection
    ) -> None:
        super().__init__(spec, index, restarts)
        self.connection = connection
        self.control = -1
        self.remote_status: dict[str, float] | None = None
        self.lost = False

    def spawn(
        self,
        clock: Callable[[], float] = time.monotonic,
        extra_env: Mapping[str, str] | None = None,
    ) -> None:
        self.connection.acquire()  # raises ConnectError (an OSError): "failed to start"
        try:
            self._start_client(clock, extra_env)
        except BaseException:
            self.connection.release()
            raise

    def _start_client(
        self, clock: Callable[[], float], extra_env: Mapping[str, str] | None
    ) -> None:
        program = agent_program(self.spec)
        argv = self.connection.ssh_command(remote_command(self.connection.machine))
        env = {**self.connection.environ, **(extra_env or {})}
        self.popen = subprocess.Popen(
            argv,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
            start_new_session=True,
            close_fds=True,
        )
        self.pid = self.popen.pid
        self.started_at = clock()
        assert self.popen.stdin is not None
        self.control = self.popen.stdin.fileno()
        _fit_pipe(self.control, len(program))
        try:
            _write_all(self.control, program)
        except OSError:
            pass  # the client is already gone: its exit says why
        os.set_blocking(self.control, False)
        self.watch_pipes()

    def read(self, fd: int) -> tuple[bytes, bool]:
        data, eof = super().read(fd)
        stream = self.streams.get(fd)
        if stream is None or stream.name != "stderr":
            return data, eof
        mark = agent_module.STATUS_MARK
        at = data.find(mark)
        if at >= 0 and (at == 0 or data[at - 1 : at] == b"\n"):
            end = data.find(b"\n", at)
            self.remote_status = _parse_status(data[at + len(mark) : end])
            data = data[:at] + data[end + 1 :]
            self._apply_status()
        if eof and self.remote_status is None and not self.lost:
            self.lost = True
            machine = self.connection.machine
            data += LOST.format(name=machine.name, where=machine.destination).encode()
        return data, eof

    def signal_group(self, sig: int, *, wake: bool = False) -> bool:
        """Ask the agent to signal the remote group (it adds SIGCONT); locally if it cannot."""
        if not self.pid or self.returncode is not None:
            return super().signal_group(sig, wake=wake)
        try:
            os.write(self.control, f"{sig}\n".encode())
        except (BlockingIOError, OSError):
            # The client no longer reads its stdin: end it, which ends the agent's stdin too.
            return super().signal_group(sig, wake=wake)
        self.signals_sent.append(sig)
        return True

    def reaped(
        self,
        status: int,
        clock: Callable[[], float] = time.monotonic,
        rusage: object | None = None,
    ) -> None:
        super().reaped(status, clock, rusage)  # which closes the control pipe (its stdin)
        self._apply_status()
        self.connection.release()

    def _apply_status(self) -> None:
        """The remote exit in place of the local client's, once both are known.

        The supervisor drains the pipes after ``reaped`` and reads the exit only after that, so
        a status record still in the pipe at reaping time is applied when ``read`` finds it.
        """
        status = self.remote_status
        if status is None or self.returncode is None:
            return
        code = int(status["code"])
        self.returncode = code
        self.core_dumped = bool(status.get("core", 0))
        self.peak_rss = int(status.get("rss", 0)) * 1024
        self.cpu_time = float(status.get("cpu", 0.0))
        if self.popen is not None:
            self.popen.returncode = code


def _parse_status(text: bytes) -> dict[str, float]:
    """``exit 3 rss K cpu S`` / ``signal 15 core 0 rss K cpu S`` -> code (negative: signal)."""
    words = text.decode("ascii", "replace").split()
    fields = dict(zip(words[::2], words[1::2], strict=False))
    try:
        if "signal" in fields:
            out: dict[str, float] = {"code": -int(fields["signal"])}
            out["core"] = int(fields.get("core", "0"))
        else:
            out = {"code": int(fields.get("exit", "255"))}
        out["rss"] = int(fields.get("rss", "0"))
        out["cpu"] = float(fields.get("cpu", "0"))
    except ValueError:
        return {"code": 255}
    return out


def _fit_pipe(fd: int, size: int) -> None:
    """Grow the pipe so the program fits in it (the write then never waits for ssh)."""
    if size < 65536:
        return
    try:
        fcntl.fcntl(fd, 1031, min(size + 4096, 1 << 20))  # F_SETPIPE_SZ
    except OSError:
        pass


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


class Spawner:
    """Makes the run's processes: plain ones here, ``RemoteProcess`` on other machines.

    One per run: it owns a private directory for the control sockets and the connections, one
    per machine for each ``SESSIONS_PER_CONNECTION`` processes running there. ``connect`` opens
    the machines the launch starts with before anything runs, so an unreachable machine is a
    clear error (exit 2) instead of a first node that fails.
    """

    def __init__(self, environ: Mapping[str, str], extra_env: Mapping[str, str] | None = None):
        import itertools
        import tempfile

        self.environ = dict(environ)
        self.extra_env = dict(extra_env or {})
        self.socket_dir = tempfile.mkdtemp(prefix="mlaunch-ssh-")
        self.connections: dict[MachineSpec, list[Connection]] = {}
        self._numbers = itertools.count()

    def connection(self, machine: MachineSpec) -> Connection:
        """A connection to ``machine`` with a session to spare (a new one when all are full)."""
        pool = self.connections.setdefault(machine, [])
        for conn in pool:
            if conn.users < SESSIONS_PER_CONNECTION:
                return conn
        path = os.path.join(self.socket_dir, str(next(self._numbers)))
        conn = Connection(machine, path, self.environ, self.extra_env)
        pool.append(conn)
        return conn

    def __call__(self, spec: ProcessSpec, index: int, restarts: int = 0) -> Process:
        machine = spec.machine
        if machine is None or machine.local:
            return Process(spec, index, restarts)
        return RemoteProcess(spec, index, restarts, connection=self.connection(machine))

    def connect(self, specs: list[ProcessSpec]) -> None:
        """Open (and keep, for their first processes) the connections these specs need."""
        for spec in specs:
            machine = spec.machine
            if machine is None or machine.local:
                continue
            conn = self.connection(machine)
            if conn.open:
                continue
            try:
                conn.connect()
            except ConnectError as e:
                raise MlaunchError(str(e), where=machine.origin or None) from e

    def close(self) -> None:
        """Close every connection and remove the socket directory."""
        for pool in self.connections.values():
            for conn in pool:
                conn.close()
        import shutil

        shutil.rmtree(self.socket_dir, ignore_errors=True)
