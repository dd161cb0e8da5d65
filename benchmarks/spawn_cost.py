"""The launcher's CPU to start one child: engine.spawning against Popen and os.posix_spawn.

    python benchmarks/spawn_cost.py [--children 100] [--rounds 5] [--fds 0,300] [--json]

Each way starts the same child (``true``) as mlaunch does (its own session, stdin a pipe,
stdout and stderr pipes, the environment given: this one plus 40 variables), ``--children`` in a
row, and the CPU time of the starting thread is divided by their number (the children are reaped
after the clock stops). The ways alternate within each round (the order rotated), with ``F``
other descriptors open (close-on-exec pipes, as a launch of F/3 children holds):

- ``popen``: ``subprocess.Popen(..., start_new_session=True, close_fds=True)``, the floor's way;
- ``spawning``: ``mlaunch.engine.spawning.start`` (the same C function without Popen's Python,
  the environment encoded once for every equal one), the engine's way;
- ``posix_spawn``: ``os.posix_spawn`` with ``setsid``, for reference only: before Python 3.13 it
  cannot close the descriptors a C library left inheritable, which the other two do.

Prints a table (or with ``--json`` the samples, seconds per child by way and fd count).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from mlaunch.engine import spawning  # noqa: E402

WAYS = ("popen", "spawning", "posix_spawn")


def _pipes() -> tuple[int, int, int, int, int, int]:
    stdin_r, stdin_w = os.pipe()
    out_r, out_w = os.pipe()
    err_r, err_w = os.pipe()
    return stdin_r, stdin_w, out_r, out_w, err_r, err_w


def starter(way: str, program: str, env: dict[str, str]) -> Callable[[], int]:
    """A function that starts one child the given way and returns its pid."""
    argv = [program]

    def popen() -> int:
        stdin_r, stdin_w, out_r, out_w, err_r, err_w = _pipes()
        child = subprocess.Popen(
            argv,
            stdin=stdin_r,
            stdout=out_w,
            stderr=err_w,
            env=env,
            start_new_session=True,
            close_fds=True,
        )
        child.returncode = 0  # reaped below, not by Popen
        for fd in (stdin_r, stdin_w, out_r, out_w, err_r, err_w):
            os.close(fd)
        return child.pid

    def direct() -> int:
        stdin_r, stdin_w, out_r, out_w, err_r, err_w = _pipes()
        pid = spawning.start(
            argv, spawning.environment(env), stdin=stdin_r, stdout=out_w, stderr=err_w
        )
        for fd in (stdin_r, stdin_w, out_r, out_w, err_r, err_w):
            os.close(fd)
        return pid

    def posix() -> int:
        stdin_r, stdin_w, out_r, out_w, err_r, err_w = _pipes()
        actions = [
            (os.POSIX_SPAWN_DUP2, stdin_r, 0),
            (os.POSIX_SPAWN_DUP2, out_w, 1),
            (os.POSIX_SPAWN_DUP2, err_w, 2),
        ]
        pid = os.posix_spawn(
            program,
            argv,
            env,
            file_actions=actions,
            setsid=True,
            setsigdef=(signal.SIGPIPE, signal.SIGXFSZ),
        )
        for fd in (stdin_r, stdin_w, out_r, out_w, err_r, err_w):
            os.close(fd)
        return pid

    return {"popen": popen, "spawning": direct, "posix_spawn": posix}[way]


def measure(children: int, rounds: int, fds: list[int]) -> dict[str, dict[int, list[float]]]:
    program = "/bin/true" if os.path.exists("/bin/true") else "/usr/bin/true"
    env = dict(os.environ)
    for i in range(40):
        env.setdefault(f"SPAWN_COST_{i}", "x" * 30)
    ways = [w for w in WAYS if w != "spawning" or spawning.AVAILABLE]
    samples: dict[str, dict[int, list[float]]] = {w: {n: [] for n in fds} for w in ways}
    for count in fds:
        held = [os.pipe() for _ in range(count // 2)]
        try:
            for round_no in range(rounds + 1):  # round 0 warms up
                shift = round_no % len(ways)
                for way in ways[shift:] + ways[:shift]:
                    start = starter(way, program, env)
                    before = time.thread_time()
                    pids = [start() for _ in range(children)]
                    spent = time.thread_time() - before
                    for pid in pids:
                        os.waitpid(pid, 0)
                    if round_no:
                        samples[way][count].append(spent / children)
        finally:
            for r, w in held:
                os.close(r)
                os.close(w)
    return samples


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="spawn_cost.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--children", type=int, default=100)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--fds", default="0,300", help="comma list of other fds held open")
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    fds = [int(n) for n in args.fds.split(",")]
    samples = measure(args.children, args.rounds, fds)
    if args.json:
        print(json.dumps({w: {str(n): s for n, s in by.items()} for w, by in samples.items()}))
        return 0
    print(f"launcher CPU per child start, {args.children} children x {args.rounds} rounds;"
          f" load average {os.getloadavg()[0]:.2f}")  # fmt: skip
    for way, by in samples.items():
        for count, values in by.items():
            print(
                f"{way:12} {count:4d} fds open: best {min(values) * 1e6:6.1f} us,"
                f" median {statistics.median(values) * 1e6:6.1f} us"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
