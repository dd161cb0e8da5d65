"""The ``plancache`` group of benchmarks/run.py: a launch resolved cold and warm, alternating in
one run (docs/plan-cache.md).

Each run of a case takes a plan cache folder of its own (``XDG_CACHE_HOME``) and runs
``mlaunch FILE --print --format json --debug`` twice: cold (no entry: loaded, resolved, recorded,
then stored) and warm (the plan from the cache). ``--debug`` says, from the moment the cache is
looked for to the plan in hand, the wall-clock and CPU time of each (``loaded and resolved in``,
``stored in``, ``inputs unchanged``); the whole command's CPU (its rusage: interpreter, imports,
writing the JSON) is measured too, warm beside the same command with ``--no-cache``. Run 0 of
each case is a warm-up.
"""

from __future__ import annotations

import os
import re
import subprocess
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from autoware_bench import Figure  # one row of the table, as the autoware group's
from probes import BenchError

COLD = re.compile(
    r"loaded and resolved in (\d+) ms, CPU (\d+) ms; stored in (\d+) ms, CPU (\d+) ms"
)
WARM = re.compile(r"inputs unchanged; (\d+) ms, CPU (\d+) ms")
TARGET_S = 0.1  # issue 37: a repeated start of the same big tree resolves in under 0.1 s


@dataclass(frozen=True)
class Case:
    """A launch to resolve: its name in the table, the command line after ``mlaunch``, its env."""

    name: str
    argv: list[str]
    env: dict[str, str]


@dataclass
class Samples:
    cold_wall: list[float] = field(default_factory=list)
    cold_cpu: list[float] = field(default_factory=list)
    store_cpu: list[float] = field(default_factory=list)
    warm_wall: list[float] = field(default_factory=list)
    warm_cpu: list[float] = field(default_factory=list)
    warm_command: list[float] = field(default_factory=list)
    no_cache_command: list[float] = field(default_factory=list)


def run(argv: Sequence[str], env: dict[str, str], timeout: float = 120.0) -> tuple[str, float]:
    """(stderr, CPU seconds of the command and its reaped children); BenchError if it fails."""
    started = time.perf_counter()
    proc = subprocess.Popen(
        list(argv),
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    assert proc.stderr is not None
    err = proc.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    proc.stderr.close()
    code = os.waitstatus_to_exitcode(status)
    if code != 0 or time.perf_counter() - started > timeout:
        last = err.strip().splitlines()[-1:] or [""]
        raise BenchError(f"{' '.join(argv[:2])}: exit {code}: {last[0]}")
    return err, usage.ru_utime + usage.ru_stime


def _said(pattern: re.Pattern[str], err: str, what: str) -> tuple[int, ...]:
    match = pattern.search(err)
    if match is None:
        lines = [x for x in err.splitlines() if "plan cache" in x] or err.splitlines()[-1:]
        raise BenchError(f"the {what} run did not say its times: {' / '.join(lines)[:300]}")
    return tuple(int(x) for x in match.groups())


def measure_case(case: Case, mlaunch: Path, runs: int, tmp: Path) -> Samples:
    samples = Samples()
    command = [str(mlaunch), *case.argv, "--print", "--format", "json"]
    slug = re.sub(r"[^a-z0-9]+", "-", case.name.lower())
    for i in range(runs + 1):
        env = {**case.env, "XDG_CACHE_HOME": str(tmp / f"plancache-{slug}-{i}")}
        env.pop("MLAUNCH_NO_CACHE", None)
        err, _ = run([*command, "--debug"], env)
        cold = _said(COLD, err, "cold")
        err, warm_command = run([*command, "--debug"], env)
        warm = _said(WARM, err, "warm")
        _, no_cache_command = run([*command, "--no-cache"], env)
        if not i:
            continue
        samples.cold_wall.append(cold[0] / 1000)
        samples.cold_cpu.append(cold[1] / 1000)
        samples.store_cpu.append(cold[3] / 1000)
        samples.warm_wall.append(warm[0] / 1000)
        samples.warm_cpu.append(warm[1] / 1000)
        samples.warm_command.append(warm_command)
        samples.no_cache_command.append(no_cache_command)
    return samples


def measure(
    runs: int, mlaunch: Path, cases: Sequence[Case], tmp: Path, say: Callable[[str], None]
) -> list[Figure]:
    figures: list[Figure] = []
    for case in cases:
        say(f"plancache: {case.name} ({runs} runs and a warm-up) ...")
        s = measure_case(case, mlaunch, runs, tmp)
        cold = "cold: loaded, resolved, recorded"
        figures += [
            Figure(
                f"plan cache, {case.name}: resolve CPU, warm", "s", s.warm_cpu, cold, s.cold_cpu,
                TARGET_S,
            ),
            Figure(
                f"plan cache, {case.name}: resolve wall, warm", "s", s.warm_wall, cold,
                s.cold_wall, TARGET_S, "wall-clock: the machine's load shows here",
            ),
            Figure(f"plan cache, {case.name}: storing the plan CPU, cold run", "s", s.store_cpu),
            Figure(
                f"plan cache, {case.name}: --print command CPU, warm", "s", s.warm_command,
                "--no-cache", s.no_cache_command,
            ),
        ]  # fmt: skip
    return figures
