"""Where the test suite's time goes: the suite run as scripts/check runs it, each test timed.

    .venv/bin/python benchmarks/suite_time.py [--workers 4] [--json FILE] [--keep DIR]
                                               [-- PYTEST ARGS ...]

Runs pytest on the workers (``-n 4 --dist worksteal``, as scripts/check) with a plugin
(suite_timeline.py) that writes each test's start, end and CPU, then prints: the wall time, the
summed test durations, the CPU of the run (pytest and every process it reaped), the load average
before and after (on a shared machine wall times say more about the neighbours than about the
suite: compare CPU and summed durations), each worker's busy and idle time (idle: between its
tests, as while a serial test drains the run, and after its last), the files and tests that
cost the most time and CPU, and the last tests to end. ``--json`` writes the same as data.
Without ``-- ARGS`` the whole suite runs (about 10 minutes on 2 cores when quiet).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent


def read_timeline(folder: Path) -> list[dict[str, Any]]:
    rows = []
    for path in sorted(folder.glob("tl-*.jsonl")):
        worker = path.name[3:-6]
        for line in path.read_text().splitlines():
            row = json.loads(line)
            row["worker"] = worker
            rows.append(row)
    return rows


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The figures of a timeline: per worker, per file, per test."""
    if not rows:
        return {"tests": 0}
    first = min(r["start"] for r in rows)
    last = max(r["end"] for r in rows)
    workers: dict[str, dict[str, float]] = {}
    by_worker: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        by_worker[row["worker"]].append(row)
    for worker, own in sorted(by_worker.items()):
        own.sort(key=lambda r: r["start"])
        busy = sum(r["end"] - r["start"] for r in own)
        between = sum(b["start"] - a["end"] for a, b in itertools.pairwise(own))
        workers[worker] = {
            "tests": len(own),
            "busy_s": busy,
            "idle_between_s": between,
            "idle_at_end_s": last - own[-1]["end"],
        }
    files: dict[str, dict[str, float]] = defaultdict(lambda: {"tests": 0, "s": 0.0, "cpu_s": 0.0})
    for row in rows:
        entry = files[row["id"].split("::")[0]]
        entry["tests"] += 1
        entry["s"] += row["end"] - row["start"]
        entry["cpu_s"] += row["cpu_self"] + row["cpu_children"]
    tests = [
        {
            "id": r["id"],
            "s": r["end"] - r["start"],
            "cpu_s": r["cpu_self"] + r["cpu_children"],
            "worker": r["worker"],
            "at_s": r["start"] - first,
        }
        for r in rows
    ]
    return {
        "tests": len(rows),
        "span_s": last - first,
        "summed_s": sum(t["s"] for t in tests),
        "tests_cpu_s": sum(t["cpu_s"] for t in tests),
        "workers": workers,
        "files": dict(files),
        "longest": sorted(tests, key=lambda t: -t["s"])[:25],
        "costliest": sorted(tests, key=lambda t: -t["cpu_s"])[:25],
        "last_to_end": sorted(tests, key=lambda t: -(t["at_s"] + t["s"]))[:8],
    }


def report(result: dict[str, Any]) -> str:
    s = result["summary"]
    lines = [
        f"suite: {s.get('tests', 0)} tests, wall {result['wall_s']:.0f} s"
        f" (pytest's exit status {result['status']}), load average {result['load_before']}"
        f" before, {result['load_after']} after",
    ]
    if not s.get("tests"):
        return "\n".join(lines)
    lines += [
        f"summed test durations {s['summed_s']:.0f} s; CPU of the run {result['cpu_s']:.0f} s"
        f" (of it in the tests, as their workers reaped it: {s['tests_cpu_s']:.0f} s)",
        "",
        "worker  tests  busy s  idle between s  idle at end s",
    ]
    for worker, w in s["workers"].items():
        lines.append(
            f"{worker:6} {w['tests']:6} {w['busy_s']:7.0f} {w['idle_between_s']:15.0f}"
            f" {w['idle_at_end_s']:14.0f}"
        )
    lines += ["", "files by summed duration (s, CPU s, tests):"]
    files = sorted(s["files"].items(), key=lambda kv: -kv[1]["s"])
    for name, f in files[:20]:
        lines.append(f"  {f['s']:7.1f} {f['cpu_s']:6.1f} {f['tests']:4.0f}  {name}")
    lines += ["", "files by CPU (CPU s, s, tests):"]
    for name, f in sorted(s["files"].items(), key=lambda kv: -kv[1]["cpu_s"])[:15]:
        lines.append(f"  {f['cpu_s']:6.1f} {f['s']:7.1f} {f['tests']:4.0f}  {name}")
    lines += ["", "longest tests (s, CPU s, worker, started at s):"]
    for t in s["longest"][:15]:
        lines.append(
            f"  {t['s']:6.1f} {t['cpu_s']:5.1f} {t['worker']} @{t['at_s']:5.0f}  {t['id']}"
        )
    lines += ["", "last to end (s, worker, from-to s):"]
    for t in s["last_to_end"]:
        end = t["at_s"] + t["s"]
        lines.append(f"  {t['s']:6.1f} {t['worker']} {t['at_s']:5.0f}-{end:5.0f}  {t['id']}")
    return "\n".join(lines)


def load() -> str:
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=4, help="pytest-xdist workers (4)")
    parser.add_argument("--json", type=Path, help="write the figures as JSON to FILE")
    parser.add_argument("--keep", type=Path, help="keep the per-worker timelines in DIR")
    parser.add_argument("pytest_args", nargs="*", help="after --: pytest's (default: all tests)")
    args = parser.parse_args(argv)
    folder = args.keep or Path(tempfile.mkdtemp(prefix="suite-time-"))
    folder.mkdir(parents=True, exist_ok=True)
    for old in folder.glob("tl-*.jsonl"):
        old.unlink()
    env = dict(os.environ, SUITE_TIMELINE_DIR=str(folder))
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(HERE), env.get("PYTHONPATH")) if p)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # as scripts/check
    for name in [n for n in env if n.startswith("PYTEST_XDIST_")]:
        del env[name]  # run from an xdist worker (a test): not one of its workers
    command = [sys.executable, "-m", "pytest", "-p", "suite_timeline", "-q"]
    if args.workers > 0:
        command += ["-n", str(args.workers), "--dist", "worksteal"]
    command += args.pytest_args
    before, started = load(), time.monotonic()
    reaped = resource.getrusage(resource.RUSAGE_CHILDREN)
    status = subprocess.run(command, cwd=REPO, env=env, check=False).returncode
    wall = time.monotonic() - started
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = {
        "command": command,
        "status": status,
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime - reaped.ru_utime - reaped.ru_stime,
        "load_before": before,
        "load_after": load(),
        "summary": summarize(read_timeline(folder)),
    }
    print(report(result))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
    return status


if __name__ == "__main__":
    sys.exit(main())
