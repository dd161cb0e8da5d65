"""The agent: the small program mlaunch runs on another computer for each remote process.

This file is sent as text through ssh and run by the remote ``python3`` (standard library only,
nothing of mlaunch is installed there). ``BOOTSTRAP`` is the whole command line: it reads a
length-prefixed program (this file plus a JSON config) from stdin and runs ``main``. The rest
of stdin is the control channel from mlaunch.

What the agent guarantees, whatever happens to mlaunch or the network:
- the process runs in a session (and so a process group) of its own on the remote;
- a control line ``N`` from mlaunch sends signal N to that group (with SIGCONT, so a stopped
  process handles it); this is how mlaunch's stop ladder reaches the remote group;
- when stdin ends (mlaunch exited, was killed, or the connection broke), or the agent's own
  output can no longer be written, the group gets SIGTERM and, after ``grace`` seconds, SIGKILL:
  nothing keeps running on a robot after the launcher is gone;
- when the process exits, the rest of its group gets the same treatment, so the remote group
  ends with its leader;
- params files come inside the config and are written to a private temp dir that is removed
  when the agent leaves;
- the last line on stderr is a status record (``STATUS_MARK`` + ``exit N`` or ``signal N``
  with core/peak memory/CPU), which mlaunch turns back into the exit code and signal.
"""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time

STATUS_MARK = b"\x1emlaunch-status "
POLL = 0.1

# The command line run on the remote (through env-loader when the machine has one). The
# program and its config come on stdin, as "<length>\n<program>"; what follows is control.
BOOTSTRAP = """import os,sys
b=b''
while 1:
    i=b.find(b'\\n')
    if i>=0 and len(b)>i+int(b[:i]):
        break
    c=os.read(0,65536)
    if not c:
        sys.exit(255)
    b+=c
n=int(b[:i])
g={'__name__':'mlaunch_agent'}
exec(compile(b[i+1:i+1+n],'mlaunch-agent','exec'),g)
g['main'](b[i+1+n:])
"""


class Agent:
    """One remote process: its child, its pipes, the control channel and the ending."""

    def __init__(self, config: dict) -> None:  # type: ignore[type-arg]
        self.config = config
        self.grace = float(config.get("grace", 5.0))
        self.temp_dir: str | None = None
        self.child: subprocess.Popen[bytes] | None = None
        self.status: str | None = None
        self.control = b""
        self.lost = False
        self.kill_at: float | None = None
        self.last_err = b"\n"

    @property
    def pid(self) -> int:
        assert self.child is not None
        return self.child.pid

    def start(self) -> None:
        argv = list(self.config["argv"])
        files = self.config.get("files") or []
        if files:
            self.temp_dir = tempfile.mkdtemp(prefix="mlaunch-")
            for index, name, data in files:
                path = os.path.join(self.temp_dir, name)
                with open(path, "wb") as f:
                    f.write(base64.b64decode(data))
                argv[index] = path
        node = self.config.get("node")
        if node:
            index, package, executable = node
            argv[index] = find_executable(package, executable, argv[index])
        env = dict(os.environ)
        for key, value in self.config.get("env", {}).items():
            if value is None:
                env.pop(key, None)
            else:
                env[key] = value
        cwd = self.config.get("cwd") or None
        if self.config.get("shell"):
            argv = ["/bin/sh", "-c", " ".join(argv)]
        self.child = subprocess.Popen(
            argv,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
            cwd=cwd,
            start_new_session=True,
        )

    def signal_group(self, sig: int) -> None:
        if self.child is None:
            return
        try:
            os.killpg(self.pid, sig)
            if sig not in (signal.SIGKILL, signal.SIGCONT):
                os.killpg(self.pid, signal.SIGCONT)
        except OSError:
            pass

    def group_alive(self) -> bool:
        try:
            os.killpg(self.pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True

    def end_group(self) -> None:
        """SIGTERM now, SIGKILL after the grace (the loop sends it when the time comes)."""
        if self.kill_at is None:
            self.signal_group(signal.SIGTERM)
            self.kill_at = time.monotonic() + self.grace

    def on_control(self, data: bytes) -> None:
        self.control += data
        while b"\n" in self.control:
            line, self.control = self.control.split(b"\n", 1)
            try:
                self.signal_group(int(line))
            except ValueError:
                pass

    def lose(self) -> None:
        """mlaunch is gone (stdin ended) or our output cannot be written: end everything."""
        self.lost = True
        self.end_group()

    def write(self, fd: int, data: bytes) -> None:
        try:
            while data:
                data = data[os.write(fd, data) :]
        except OSError:
            if not self.lost:
                self.lose()
            return

    def run(self, pending: bytes) -> None:
        if pending:
            self.on_control(pending)
        assert self.child is not None and self.child.stdout and self.child.stderr
        pipes = {self.child.stdout.fileno(): 1, self.child.stderr.fileno(): 2}
        for fd in pipes:
            os.set_blocking(fd, False)
        watching = [0, *pipes]
        drain_until: float | None = None
        while True:
            if self.status is None:
                self.reap()
            now = time.monotonic()
            if self.kill_at is not None and now >= self.kill_at:
                self.signal_group(signal.SIGKILL)
                self.kill_at = float("inf")
            if self.status is not None:
                if self.group_alive():
                    self.end_group()
                elif drain_until is None:
                    # The group is gone: what is left in the pipes comes now, or never (an
                    # escaped descendant may hold them open).
                    drain_until = now + 0.5
            if drain_until is not None and (now >= drain_until or not set(watching) - {0}):
                break
            fds = watching if not self.lost else [fd for fd in watching if fd != 0]
            try:
                ready, _, _ = select.select(fds, [], [], POLL)
            except InterruptedError:
                continue
            for fd in ready:
                try:
                    data = os.read(fd, 65536)
                except BlockingIOError:
                    continue
                except OSError:
                    data = b""
                if fd == 0:
                    if data:
                        self.on_control(data)
                    else:
                        watching.remove(0)
                        self.lose()
                    continue
                if not data:
                    watching.remove(fd)
                    continue
                if pipes[fd] == 2:
                    self.last_err = data[-1:]
                self.write(pipes[fd], data)

    def reap(self) -> None:
        assert self.child is not None
        try:
            pid, status, usage = os.wait4(self.child.pid, os.WNOHANG)
        except ChildProcessError:
            self.status = "exit 255"
            return
        if pid == 0:
            return
        self.child.returncode = 0  # reaped here: Popen must not wait for it again
        if os.WIFSIGNALED(status):
            what = f"signal {os.WTERMSIG(status)} core {int(os.WCOREDUMP(status))}"
        else:
            what = f"exit {os.WEXITSTATUS(status)}"
        cpu = usage.ru_utime + usage.ru_stime
        self.status = f"{what} rss {usage.ru_maxrss} cpu {cpu:.3f}"

    def finish(self) -> None:
        if self.temp_dir:
            shutil.rmtree(self.temp_dir, ignore_errors=True)
        if self.status is not None and not self.lost:
            record = STATUS_MARK + self.status.encode() + b"\n"
            self.write(2, (b"" if self.last_err == b"\n" else b"\n") + record)


def find_executable(package: str, executable: str, hint: str) -> str:
    """PKG's EXE under this computer's AMENT_PREFIX_PATH, else the path mlaunch found."""
    for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if not prefix:
            continue
        path = os.path.join(prefix, "lib", package, executable)
        if os.access(path, os.X_OK) and not os.path.isdir(path):
            return path
    return hint


def main(rest: bytes) -> None:
    config = json.loads(globals()["CONFIG"])  # appended to this text by mlaunch
    agent = Agent(config)
    # The launcher's end must end us through stdin, not by a signal that skips the ending. A
    # handler, not SIG_IGN: an ignored signal would stay ignored in the child after exec.
    for sig in (signal.SIGHUP, signal.SIGINT):
        signal.signal(sig, lambda *_: None)
    signal.signal(signal.SIGTERM, lambda *_: agent.lose())
    try:
        agent.start()
    except OSError as e:
        program = config["argv"][0] if config["argv"] else "?"
        message = f"mlaunch agent: failed to start {program!r} on this computer: {e.strerror}\n"
        agent.write(2, message.encode())
        agent.status = "exit 127 rss 0 cpu 0"
        agent.finish()
        return
    try:
        agent.run(rest)
    finally:
        if agent.status is None and agent.child is not None:
            agent.signal_group(signal.SIGKILL)
            agent.child.wait()
        agent.finish()
    sys.exit(0)
