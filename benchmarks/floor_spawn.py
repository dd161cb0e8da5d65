"""The floor for start-up, shutdown and memory: a bare loop that Popen()s N children.

Usage: python floor_spawn.py N PROGRAM [ARGS...]

Each child is started the way mlaunch starts one (its own session, stdin from /dev/null,
stdout and stderr on pipes, other fds closed), and nothing else is done: no launch file, no
log files, no output handling. On SIGINT it does what a launcher must at least do: SIGINT to
every child's process group, wait for each, exit. Run with the same interpreter as the mlaunch
it is compared with, so both pay the same interpreter start-up.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from types import FrameType


def main(argv: list[str]) -> int:
    if len(argv) < 2 or not argv[0].isdigit():
        print("usage: floor_spawn.py N PROGRAM [ARGS...]", file=sys.stderr)
        return 2
    count, command = int(argv[0]), argv[1:]
    children: list[subprocess.Popen[bytes]] = []
    state = {"spawned": False, "requested": False}

    def stop() -> None:
        for child in children:
            try:
                os.killpg(child.pid, signal.SIGINT)
            except ProcessLookupError:
                pass
        for child in children:
            child.wait()
        os._exit(128 + signal.SIGINT)

    def on_sigint(signum: int, frame: FrameType | None) -> None:
        # A SIGINT inside Popen() (the child already running, not yet in the list) must not
        # stop early and leave that child behind: it is acted on once every child is listed.
        state["requested"] = True
        if state["spawned"]:
            stop()

    signal.signal(signal.SIGINT, on_sigint)
    for _ in range(count):
        children.append(
            subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                start_new_session=True,
                close_fds=True,
            )
        )
    state["spawned"] = True
    if state["requested"]:
        stop()
    while True:
        signal.pause()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
