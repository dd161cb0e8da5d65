"""Where resolving Autoware's tree spends its CPU: ``mlaunch --print`` of the fixture, sampled.

    .venv/bin/python benchmarks/autoware_profile.py [--interval MS] [--top N]

Runs ``mlaunch --print`` of the planning_simulator fixture (``autoware_tree.py`` must have got
the sources) in this process under a statistical sampler: every ``--interval`` ms of CPU
(SIGPROF) it notes every function on the stack, so the table gives each function's inclusive
share of the CPU. A deterministic profiler (cProfile) triples the run and inflates small, often
called functions (it made the frame walk of ``caller_origin`` look like 12 % of the time; it is
1 %). Imports made while resolving are counted (the tree loads launch_ros, PyYAML, xacro...).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import os
import signal
import sys
import time
from types import FrameType

import autoware_tree as fixture


class Sampler:
    """Inclusive sample counts per function (file:name), from SIGPROF."""

    def __init__(self, interval: float) -> None:
        self.interval = interval
        self.samples = 0
        self.inclusive: collections.Counter[str] = collections.Counter()

    def _sample(self, signum: int, frame: FrameType | None) -> None:
        self.samples += 1
        seen = set()
        while frame is not None:
            code = frame.f_code
            name = code.co_filename.split("site-packages/")[-1]
            name = name.split(str(fixture.REPO) + os.sep)[-1]
            seen.add(f"{name}:{code.co_name}")
            frame = frame.f_back
        self.inclusive.update(seen)

    def __enter__(self) -> Sampler:
        signal.signal(signal.SIGPROF, self._sample)
        signal.setitimer(signal.ITIMER_PROF, self.interval, self.interval)
        return self

    def __exit__(self, *exc: object) -> None:
        signal.setitimer(signal.ITIMER_PROF, 0, 0)
        signal.signal(signal.SIGPROF, signal.SIG_DFL)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--interval", type=float, default=2.0, help="ms of CPU between samples")
    parser.add_argument("--top", type=int, default=40, help="rows to print")
    args = parser.parse_args(argv)
    sources = fixture.CACHE / "sources"
    if not fixture.have_sources(sources):
        print(f"autoware_profile: no sources in {sources}: run autoware_tree.py", file=sys.stderr)
        return 1
    tree = fixture.build(sources)
    os.environ.update(tree.environ(dict(os.environ)))
    from mlaunch.cli import main as mlaunch

    started = time.process_time()
    with Sampler(args.interval / 1000) as sampler, contextlib.redirect_stdout(io.StringIO()):
        code = mlaunch(["--print", str(tree.launch_file), *tree.arguments])
    cpu = time.process_time() - started
    if code != 0:
        print(f"autoware_profile: mlaunch --print exited {code}", file=sys.stderr)
        return 1
    total = max(sampler.samples, 1)
    print(f"mlaunch --print of the tree: {cpu * 1000:.0f} ms CPU, {sampler.samples} samples")
    print("inclusive share of the samples, by function:")
    for name, count in sampler.inclusive.most_common(args.top):
        print(f"  {100 * count / total:5.1f} %  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
