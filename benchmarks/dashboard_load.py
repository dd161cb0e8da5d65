"""What browsers on the launch panel cost a run: mlaunch's CPU and its output latency with 0, 1
and 20 pages open.

    .venv/bin/python benchmarks/dashboard_load.py [--seconds S] [--pages 1,20]

A launch whose one process prints a line stamped with the monotonic clock every 10 ms runs
under mlaunch --dashboard; mlaunch's stdout is read by a thread that notes when each line
arrives, so each line's delay through mlaunch is measured. For each number of pages, that many
pages are opened as the panel's script opens them (its one stream: the state, and a log view
following the printing process; a quarter of them never read what they are sent, as a stuck
tab), and
mlaunch's own CPU time (/proc/PID/stat: user + system, its threads included) is read over the
window. ``tests/test_dashboard_load.py`` uses ``Pages`` and ``Stamps`` with a shorter window.
"""

from __future__ import annotations

import argparse
import os
import selectors
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

STAMP = (
    "import time\n"
    "i = 0\n"
    "while True:\n"
    "    print('s', i, f'{time.monotonic():.6f}', flush=True); i += 1; time.sleep(0.01)\n"
)
LAUNCH = f"""from launch import LaunchDescription
from launch.actions import ExecuteProcess
def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[{sys.executable!r}, "-c", {STAMP!r}], name="stamp", output="screen"),
    ])
"""
OPEN = b"dashboard: open http://127.0.0.1:"


class Stamps(threading.Thread):
    """Reads mlaunch's stdout; ``delays`` holds (arrival, delay) of each stamped line."""

    def __init__(self, fd: int) -> None:
        super().__init__(daemon=True)
        self.fd = fd
        self.delays: list[tuple[float, float]] = []
        self.port = 0
        self.ready = threading.Event()
        self._partial = b""

    def run(self) -> None:
        while True:
            try:
                got = os.read(self.fd, 65536)
            except OSError:
                break
            if not got:
                break
            now = time.monotonic()
            *lines, self._partial = (self._partial + got).split(b"\n")
            for line in lines:
                if line.startswith(b"[stamp-1] s "):
                    self.delays.append((now, now - float(line.split()[-1])))
                elif OPEN in line:
                    self.port = int(line.split(OPEN)[1].split(b"/")[0])
                    self.ready.set()
        self.ready.set()

    def between(self, start: float, end: float) -> list[float]:
        return [delay for arrived, delay in self.delays if start <= arrived < end]


class Pages(threading.Thread):
    """``count`` pages on the panel at 127.0.0.1:port, each with its stream (the state and a log
    view of ``label``); every fourth page never reads (a stuck tab). One thread, one selector."""

    def __init__(self, port: int, count: int, label: str = "stamp-1") -> None:
        super().__init__(daemon=True)
        self.selector = selectors.DefaultSelector()
        self.sockets: list[socket.socket] = []
        self.received = 0
        self._done = threading.Event()
        paths = (f"/launch/events?follow={label}&lines=50",)
        for page in range(count):
            for path in paths:
                conn = socket.create_connection(("127.0.0.1", port), timeout=10)
                request = f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n"
                conn.sendall(request.encode())
                conn.setblocking(False)
                self.sockets.append(conn)
                if page % 4 != 3:
                    self.selector.register(conn, selectors.EVENT_READ)

    def run(self) -> None:
        while not self._done.is_set():
            for key, _ in self.selector.select(0.1):
                conn = key.fileobj
                assert isinstance(conn, socket.socket)
                try:
                    data = conn.recv(65536)
                except BlockingIOError:
                    continue
                except OSError:
                    data = b""
                if not data:
                    self.selector.unregister(conn)
                self.received += len(data)

    def close(self) -> None:
        self._done.set()
        self.join(5)
        for conn in self.sockets:
            conn.close()
        self.selector.close()


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of process ``pid`` (all its threads), in seconds."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(") ", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def start(folder: Path, python: str = sys.executable) -> tuple[subprocess.Popen[bytes], Stamps]:
    """mlaunch --dashboard on the stamping launch, with its stdout read by Stamps."""
    launch = folder / "stamp.launch.py"
    launch.write_text(LAUNCH)
    env = {**os.environ, "ROS_LOG_DIR": str(folder / "logs"), "NO_COLOR": "1"}
    proc = subprocess.Popen(
        [python, "-m", "mlaunch", str(launch), "--dashboard"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
        env=env,
        cwd=str(folder),
        start_new_session=True,
    )
    assert proc.stdout is not None
    stamps = Stamps(proc.stdout.fileno())
    stamps.start()
    if not stamps.ready.wait(60) or not stamps.port:
        proc.kill()
        raise RuntimeError("mlaunch did not say the panel's address")
    return proc, stamps


def window(
    proc: subprocess.Popen[bytes], stamps: Stamps, port: int, pages: int, seconds: float
) -> dict[str, float]:
    """``pages`` pages open for ``seconds``: mlaunch's CPU (percent of one core) and the
    median and 95th percentile of the lines' delay, in ms."""
    opened = Pages(port, pages) if pages else None
    if opened is not None:
        opened.start()
    time.sleep(0.5)  # the pages' first messages are sent; measure the steady state
    begin, cpu0 = time.monotonic(), cpu_seconds(proc.pid)
    time.sleep(seconds)
    end, cpu1 = time.monotonic(), cpu_seconds(proc.pid)
    received = 0
    if opened is not None:
        opened.close()
        received = opened.received
    delays = sorted(stamps.between(begin, end))
    return {
        "pages": pages,
        "cpu": 100 * (cpu1 - cpu0) / (end - begin),
        "median_ms": 1000 * statistics.median(delays),
        "p95_ms": 1000 * delays[int(0.95 * (len(delays) - 1))],
        "lines": len(delays),
        "received": received,  # bytes the reading pages got
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--pages", default="1,20")
    args = parser.parse_args()
    counts = [0] + [int(n) for n in args.pages.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        proc, stamps = start(Path(tmp))
        try:
            time.sleep(2.0)  # past start-up
            print("pages  mlaunch CPU  median delay  p95 delay  lines")
            for count in counts:
                r = window(proc, stamps, stamps.port, count, args.seconds)
                print(
                    f"{count:5d}  {r['cpu']:10.1f}%  {r['median_ms']:9.2f} ms"
                    f"  {r['p95_ms']:6.2f} ms  {r['lines']:5.0f}"
                )
        finally:
            proc.send_signal(2)
            proc.wait(30)
    return 0


if __name__ == "__main__":
    sys.exit(main())
