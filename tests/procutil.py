"""The tests' shared helpers: run mlaunch as a real process and read its output with deadlines,
and wait for a condition with a deadline (wait_until, wait_for), never a bare sleep."""

from __future__ import annotations

import os
import re
import selectors
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")
REPO = Path(__file__).resolve().parent.parent


def demo_package(root: Path) -> str:
    """An ament prefix under ``root`` with package ``demo`` and its executable ``talker`` (a
    Python script printing 'talking'); returns the prefix, for AMENT_PREFIX_PATH."""
    talker = f"#!{sys.executable}\nprint('talking')\n"
    return str(install_package(root / "install", "demo", {"talker": talker}))


def clean_env(**extra: str) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["NO_COLOR"] = "1"
    env.update(extra)
    return env


class Running:
    """mlaunch (or any command) started with its output on a pipe we can wait on."""

    def __init__(self, argv: Sequence[str], *, env: dict[str, str], cwd: str | None = None) -> None:
        self.proc = subprocess.Popen(
            list(argv),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            env=env,
            cwd=cwd,
            start_new_session=True,
        )
        assert self.proc.stdout is not None
        os.set_blocking(self.proc.stdout.fileno(), False)
        self.text = ""
        self._sel = selectors.DefaultSelector()
        self._sel.register(self.proc.stdout, selectors.EVENT_READ)

    def _pump(self, timeout: float) -> bool:
        """Read what is available within timeout; False at EOF."""
        assert self.proc.stdout is not None
        if not self._sel.select(timeout):
            return True
        chunk = self.proc.stdout.read()
        if not chunk:
            return False
        self.text += chunk.decode("utf-8", "replace")
        return True

    def wait_for(self, pattern: str, timeout: float = 10.0) -> re.Match[str]:
        deadline = time.monotonic() + timeout
        regex = re.compile(pattern, re.M)
        while True:
            match = regex.search(self.text)
            if match:
                return match
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(
                    f"timed out waiting for {pattern!r}; output so far:\n{self.text}"
                )
            if not self._pump(min(left, 0.2)) and not regex.search(self.text):
                raise AssertionError(f"EOF before {pattern!r}; output:\n{self.text}")

    def finish(self, timeout: float = 20.0) -> int:
        deadline = time.monotonic() + timeout
        while self._pump(max(0.0, min(0.2, deadline - time.monotonic()))):
            if time.monotonic() > deadline:
                self.kill()
                raise AssertionError(f"did not finish in {timeout} s; output:\n{self.text}")
        return self.proc.wait(timeout=max(0.1, deadline - time.monotonic()))

    def signal(self, sig: int) -> None:
        self.proc.send_signal(sig)

    def kill(self) -> None:
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.proc.wait(timeout=5)


def install_package(prefix: Path, package: str, programs: dict[str, str]) -> Path:
    """An install prefix holding ``package`` (its ament index marker, share and lib folders)
    with executable ``programs`` (name -> file text) in lib/<package>; returns ``prefix``."""
    (prefix / "share/ament_index/resource_index/packages").mkdir(parents=True, exist_ok=True)
    (prefix / "share/ament_index/resource_index/packages" / package).write_text("")
    (prefix / "share" / package).mkdir(exist_ok=True)
    (prefix / "lib" / package).mkdir(parents=True, exist_ok=True)
    for name, text in programs.items():
        program = prefix / "lib" / package / name
        program.write_text(text)
        program.chmod(0o755)
    return prefix


def mlaunch(*args: str) -> list[str]:
    return [sys.executable, "-m", "mlaunch", *args]


def run_mlaunch(
    *args: str, env: dict[str, str], timeout: float = 30.0
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        mlaunch(*args),
        capture_output=True,
        text=True,
        env=env,
        timeout=timeout,
        stdin=subprocess.DEVNULL,
    )


def wait_until(
    predicate: Callable[[], object], timeout: float = 10.0, interval: float = 0.02
) -> bool:
    """Poll a condition until it holds or the deadline passes (the wait itself, not a sync sleep).

    The one polling helper of the tests: False when the deadline passed (the caller asserts).
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(interval)
    return bool(predicate())


def wait_for(
    predicate: Callable[[], T | None], timeout: float, what: str, interval: float = 0.05
) -> T:
    """Poll until ``predicate()`` is truthy and return it; an AssertionError naming ``what`` when
    the deadline passes."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


def pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ", 1)[1][0] != "Z"
    except OSError:
        return False
