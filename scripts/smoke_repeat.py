#!/usr/bin/env python3
"""Run ``mlaunch test`` on the same launch many times and count the outcomes.

    .venv/bin/python scripts/smoke_repeat.py [--runs 20] [--jobs 1] [LAUNCH [EXPECTED_STATUS]]...

Without launches it runs the issue's pair: launches/jtbot_sim.launch.py (must pass, status 0)
and tests/launches/jtbot_crash.launch.py (a node crashes 3 s in: must fail, status 1). It
prints one line per run and a tally, and exits 1 unless every run gave the expected status.
``--jobs 2`` runs two at a time, to load the machine on purpose.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.append(str(ROOT / "tests"))
import ros_domain  # noqa: E402  (the one ROS-domain lock)

PAIR = [("launches/jtbot_sim.launch.py", 0), ("tests/launches/jtbot_crash.launch.py", 1)]
RUN_TIMEOUT = 180.0


def claim_domain() -> tuple[int, int]:
    """A ROS_DOMAIN_ID nobody else on this machine holds (tests/ros_domain.py, the lock the test
    suite takes), and that no leftover process of an earlier run still uses."""
    return ros_domain.claim(skip=_in_use)


def _in_use(domain: int) -> bool:
    """Whether a process on this machine has ROS_DOMAIN_ID=domain in its environment."""
    marker = f"ROS_DOMAIN_ID={domain}".encode()
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/environ", "rb") as f:
                if marker in f.read().split(b"\0"):
                    return True
        except OSError:
            continue
    return False


def one_run(launch: str, index: int) -> tuple[int, float, str]:
    domain, lock = claim_domain()
    try:
        return _run(launch, domain)
    finally:
        os.close(lock)


def _run(launch: str, domain: int) -> tuple[int, float, str]:
    started = time.monotonic()
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), NO_COLOR="1")
    env.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    done = subprocess.run(
        [sys.executable, "-m", "mlaunch", "test", launch],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
        stdin=subprocess.DEVNULL,
    )
    failed = [line.strip() for line in done.stdout.splitlines() if line.strip().startswith("FAIL")]
    # A passing run must also be a clean one: no process interrupted into a traceback.
    tracebacks = (done.stdout + done.stderr).count("Traceback")
    if tracebacks:
        failed.append(f"{tracebacks} traceback(s) in the output")
    return done.returncode, time.monotonic() - started, "; ".join(failed)[:200]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("targets", nargs="*", help="LAUNCH EXPECTED_STATUS pairs")
    args = parser.parse_args()
    if len(args.targets) % 2:
        parser.error("give launches with their expected status: LAUNCH STATUS ...")
    pairs = [(t, int(s)) for t, s in zip(args.targets[::2], args.targets[1::2], strict=True)]
    ok = True
    for launch, expected in pairs or PAIR:
        with ThreadPoolExecutor(args.jobs) as pool:
            results = list(pool.map(one_run, [launch] * args.runs, range(args.runs)))
        good = 0
        for i, (code, seconds, failed) in enumerate(results, 1):
            clean = "traceback" not in failed
            mark = "ok " if code == expected and clean else "BAD"
            good += code == expected and clean
            print(f"{mark} {launch} run {i}: status {code} in {seconds:.1f} s {failed}", flush=True)
        print(f"{launch}: {good}/{args.runs} runs gave status {expected}")
        ok &= good == args.runs
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
