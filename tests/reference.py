"""Where the reference ros2 launch (ROS 2 Jazzy's own launch system, the oracle of the
differential tests) is built: ``MLAUNCH_REFERENCE`` (what ``.ci/run`` sets, from
``scripts/reference``), else ``~/.cache/ros2-launch-jazzy`` (where its setup.sh builds it by
default). The tests that need it skip with ``MISSING`` where it is not built."""

from __future__ import annotations

import atexit
import json
import os
import select
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

HOME = Path(os.environ.get("MLAUNCH_REFERENCE") or Path.home() / ".cache" / "ros2-launch-jazzy")
ENV_SH = HOME / "env.sh"
SOURCES = HOME / "src"
MISSING = (
    f"the reference ros2 launch is not built at {HOME} (scripts/reference builds it, and"
    " MLAUNCH_REFERENCE=FOLDER names it; .ci/run does both)"
)

# Variables launch reads only when it runs: a `ros2 launch` forked by the zygote may be given
# other values than the zygote's (every other variable is the zygote's, as its start saw it).
LATE_VARIABLES = ("AMENT_PREFIX_PATH", "ROS_LOG_DIR", "CONF_RECORD_DIR", "ROS_DOMAIN_ID")
ZYGOTE = Path(__file__).resolve().parent / "reference_zygote.py"


class _Zygote:
    """One reference_zygote.py server: the reference's python with ros2cli and launch imported."""

    def __init__(self, env: dict[str, str]) -> None:
        ros2 = shutil.which("ros2", path=env.get("PATH"))
        if ros2 is None:
            raise RuntimeError(f"no ros2 on the reference's PATH {env.get('PATH')!r}")
        python = Path(ros2).read_text().splitlines()[0].removeprefix("#!").split()  # its own
        self.proc = subprocess.Popen(
            [*python, str(ZYGOTE)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
            cwd="/",
            bufsize=0,
            start_new_session=True,
        )
        self.pid = self.proc.pid
        self._buffer = b""

    def answer(self, deadline: float) -> dict[str, int]:
        """The server's next answer line, waited for until ``deadline`` (TimeoutError)."""
        assert self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        while b"\n" not in self._buffer:
            ready, _, _ = select.select([fd], [], [], max(deadline - time.monotonic(), 0.0))
            if not ready:
                raise TimeoutError
            chunk = os.read(fd, 4096)
            if not chunk:
                raise RuntimeError(f"the reference zygote ended (status {self.proc.wait()})")
            self._buffer += chunk
        line, _, self._buffer = self._buffer.partition(b"\n")
        answer: dict[str, int] = json.loads(line)
        return answer

    def close(self) -> None:
        if self.proc.stdin is not None:
            self.proc.stdin.close()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(self.pid, signal.SIGKILL)
            self.proc.wait()


_zygotes: dict[tuple[tuple[str, str], ...], _Zygote] = {}


def _close_zygotes() -> None:
    for zygote in _zygotes.values():
        zygote.close()
    _zygotes.clear()


atexit.register(_close_zygotes)


def run_ros2(
    argv: list[str], *, env: dict[str, str], cwd: Path | str, timeout: float
) -> subprocess.CompletedProcess[str]:
    """``ros2 ARGS`` (argv[0] is the reference's ros2) as subprocess.run(capture_output=True,
    text=True, stdin=DEVNULL, start_new_session=True) would run it, forked from a zygote that
    imported the reference once per test process (see reference_zygote.py)."""
    if os.environ.get("MLAUNCH_REFERENCE_ZYGOTE") == "0":  # each run a `ros2` process started cold
        return subprocess.run(
            argv,
            env=env,
            cwd=cwd,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=timeout,
            start_new_session=True,
        )
    key = tuple(sorted((k, v) for k, v in env.items() if k not in LATE_VARIABLES))
    zygote = _zygotes.get(key)
    if zygote is None or zygote.proc.poll() is not None:
        zygote = _zygotes[key] = _Zygote(dict(key))
    with tempfile.TemporaryDirectory(prefix="ros2-run-") as folder:
        out, err = Path(folder) / "stdout", Path(folder) / "stderr"
        request = {
            "argv": argv,
            "env": env,
            "cwd": str(cwd),
            "stdout": str(out),
            "stderr": str(err),
        }
        assert zygote.proc.stdin is not None
        zygote.proc.stdin.write(json.dumps(request).encode() + b"\n")
        zygote.proc.stdin.flush()
        deadline = time.monotonic() + timeout
        child = zygote.answer(deadline)["pid"]
        try:
            status = zygote.answer(deadline)["status"]
        except TimeoutError:
            os.killpg(child, signal.SIGKILL)  # as subprocess.run kills its child at the timeout
            zygote.answer(time.monotonic() + 30)
            raise subprocess.TimeoutExpired(argv, timeout) from None
        # subprocess.run's text: the locale's encoding, universal newlines
        return subprocess.CompletedProcess(
            argv, status, stdout=out.read_text(), stderr=err.read_text()
        )
