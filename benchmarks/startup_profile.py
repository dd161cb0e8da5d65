"""Where mlaunch's CPU goes on its way to the first child, bucket by bucket.

    .venv/bin/python benchmarks/startup_profile.py [--runs N] [--tree DIR] [--children N]
                                                   -- MLAUNCH [ARGS...]

Runs the command as given (the mlaunch command of the venv, with its shell script and without
the ROS wheels' re-exec, or pip's console script, or ``python -m mlaunch``) N times with a
``sitecustomize`` on ``PYTHONPATH`` (``--tree DIR`` first: another checkout of mlaunch, to compare
revisions in one run). ``site`` imports it after the ``.pth`` files, so it runs in the interpreter
that goes on to run mlaunch (the hook's re-exec, where there is one, happened before). It takes
the process's CPU time (``CLOCK_PROCESS_CPUTIME_ID``: everything since the fork, the shell
script and the re-exec included) at each step and writes them to a file when the supervisor's
first ``start`` returns (``--children N``: the N-th, the spawns after the first one bucket); mlaunch
then runs on (the launch's children should end by themselves: ``true``).

Prints the buckets (CPU, min and median over the runs) and, with ``--json``, writes them. The
bucket names are the steps of ``mlaunch.app.pipeline.launch``; a step the revision does not have
is absent. ``benchmarks/run.py --only profile`` runs it on the one-process and one-Node launches.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

# Written to a folder of its own on PYTHONPATH as sitecustomize.py. The marks are CPU seconds of
# the whole process; each bucket is the difference between two marks.
SITECUSTOMIZE = r"""
import os, sys, time
_out = os.environ.pop("MLAUNCH_STARTUP_PROFILE", "")
_children = int(os.environ.pop("MLAUNCH_STARTUP_PROFILE_CHILDREN", "1"))
_quick = os.environ.pop("MLAUNCH_STARTUP_PROFILE_QUICK", "")
if _out:  # popped: the Python programs mlaunch starts are not profiled
    _marks = [("interpreter and site (from exec)", time.process_time())]

    def _mark(name):
        _marks.append((name, time.process_time()))

    def _wrap(owner, name, label):
        original = getattr(owner, name, None)
        if original is None:
            return

        def wrapped(*args, **kwargs):
            _mark("before " + label)
            try:
                return original(*args, **kwargs)
            finally:
                _mark(label)

        setattr(owner, name, wrapped)

    _done = []

    def _finish():
        if _done:
            return
        _done.append(True)
        text = "\n".join(f"{n}\t{c!r}" for n, c in _marks)
        with open(_out + ".tmp", "w") as f:
            f.write(text + "\n")
        os.rename(_out + ".tmp", _out)

    def _setup_quick():
        # A repeated start (--quick): only what the quick start does is wrapped, nothing of the
        # rest of mlaunch imported ahead of it.
        import mlaunch.app.quick as quick
        _mark("import mlaunch.app.quick")
        _wrap(quick, "key", "quick start: the key (command line, environment, interpreter)")
        _wrap(quick.QuickStart, "_entry", "quick start: read the entry, stat its inputs and modules")
        start = quick._start
        count = [0]

        def counted(*a, **k):
            count[0] += 1
            if count[0] == 1:
                _mark("quick start: the lifeline (params folder, cgroup, guard fork), imports")
            result = start(*a, **k)
            if count[0] == 1:
                _mark("spawn of the first child")
            if count[0] >= _children:
                if _children > 1:
                    _mark(f"spawns of children 2 to {_children}")
                quick._start = start
                _finish()
            return result

        quick._start = counted

    def _setup():
        import mlaunch.cli
        _mark("import mlaunch.cli")
        import mlaunch.app.pipeline as pipeline
        import mlaunch.engine.lifeline as lifeline
        _mark("import app.pipeline (argparse, options), engine.lifeline")
        try:  # imported where it is used, since the quick start
            import mlaunch.app.options as options
        except ImportError:
            options = mlaunch.cli
        if not hasattr(options, "parse_options"):
            options = mlaunch.cli
        _wrap(options, "parse_options", "parse the command line")
        _wrap(lifeline.Lifeline, "__enter__", "lifeline (params folder, cgroup, guard fork)")
        _wrap(pipeline, "plan_cache", "plan cache: open")
        _wrap(pipeline, "load_file", "load the launch file")
        _wrap(pipeline, "resolve_for_run", "resolve")
        supervise = pipeline.supervise
        finish = _finish

        def counting(start, before_first, undo):
            # ``start`` marked around its first call and ended at the _children-th.
            count = [0]

            def started(*a, **k):
                count[0] += 1
                if count[0] == 1:
                    _mark(before_first())
                result = start(*a, **k)
                if count[0] == 1:
                    _mark("spawn of the first child")
                if count[0] < _children:
                    return result
                if _children > 1:
                    _mark(f"spawns of children 2 to {_children}")
                undo()
                finish()
                return result

            return started

        def wrap_supervisor(sup):
            start = sup.Supervisor.start

            def undo():
                sup.Supervisor.start = start

            made = lambda: "supervisor: imports, set-up, parts"  # noqa: E731
            sup.Supervisor.start = counting(start, made, undo)

        # Wraps Supervisor.start when the supervisor's module is imported (not before: a run
        # may start its first child before it imports it).
        class SupervisorHook:

            def find_spec(self, name, path, target=None):
                if name != "mlaunch.engine.supervisor":
                    return None
                sys.meta_path.remove(self)
                import importlib.util
                spec = importlib.util.find_spec(name)
                run_module = spec.loader.exec_module

                def exec_module(module):
                    run_module(module)
                    wrap_supervisor(module)

                spec.loader.exec_module = exec_module
                return spec

        def first_spawn(*args, **kwargs):
            _mark("before supervise")
            try:  # every child starts through it (before the supervisor is made, or by it)
                import mlaunch.engine.spawning as spawning
            except ImportError:
                spawning = None
            if spawning is None or not getattr(spawning, "AVAILABLE", False):
                sys.meta_path.insert(0, SupervisorHook())  # a revision that Popen()s
                return supervise(*args, **kwargs)
            spawn = spawning.start

            def undo():
                spawning.start = spawn

            def before_first():
                if "mlaunch.engine.supervisor" in sys.modules:
                    return "supervisor: imports, set-up, parts"
                return "supervise: the descriptor limit, the first spawns' set-up"

            spawning.start = counting(spawn, before_first, undo)
            return supervise(*args, **kwargs)

        pipeline.supervise = first_spawn

    if _quick:
        _setup_quick()
    else:
        _setup()
"""


def buckets(marks: list[tuple[str, float]], children: int = 1) -> dict[str, float]:
    """CPU seconds per step: the first mark itself, then the differences; the time between a
    step's end and the next step's start is its own bucket ("before X": the code in between)."""
    out: dict[str, float] = {}
    previous = 0.0
    for name, cpu in marks:
        out[name] = out.get(name, 0.0) + cpu - previous
        previous = cpu
    total = "total until the first child runs" if children == 1 else f"total to {children} started"
    out[total] = previous
    return out


def profile(
    argv: Sequence[str],
    env: dict[str, str],
    runs: int,
    tree: str | None = None,
    children: int = 1,
    quick: bool = False,
) -> dict[str, list[float]]:
    """Run ``argv`` ``runs`` times (plus a warm-up); each bucket's CPU seconds per run, until
    the first child was started, or the ``children``-th."""
    found: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory(prefix="mlaunch-profile-") as tmp:
        site = Path(tmp) / "site"
        site.mkdir()
        (site / "sitecustomize.py").write_text(SITECUSTOMIZE)
        if quick:
            # A run reads it (it is on sys.path): a quick entry is written only once every file
            # a resolution read is two seconds old (mlaunch.plan.inputs.RACY_NS).
            import time

            settled = (site / "sitecustomize.py").stat().st_ctime + 2.2
            time.sleep(max(0.0, settled - time.time()))
        paths = [p for p in (tree, str(site), env.get("PYTHONPATH")) if p]
        # The warm-up: bytecode written, caches warm; with --quick, the runs until the quick
        # start starts the children (the first writes the plan and the quick entry).
        warm = 3 if quick else 1
        measured = 0
        for i in range(runs + warm):
            if measured == runs:
                break
            out = Path(tmp) / f"marks-{i}.txt"
            run_env = {**env, "PYTHONPATH": os.pathsep.join(paths)}
            run_env["MLAUNCH_STARTUP_PROFILE"] = str(out)
            run_env["MLAUNCH_STARTUP_PROFILE_CHILDREN"] = str(children)
            if quick:
                run_env["MLAUNCH_STARTUP_PROFILE_QUICK"] = "1"
            done = subprocess.run(
                list(argv), env=run_env, capture_output=True, text=True, timeout=120
            )
            if not out.exists():
                if i < warm - 1:
                    continue  # no quick start yet
                raise RuntimeError(
                    f"no marks from {' '.join(argv)} (exit {done.returncode}):"
                    f" {done.stderr.strip()[-500:] or done.stdout.strip()[-500:]}"
                )
            if warm > 0:
                warm = 0  # the first run that has marks is the warm-up
                continue
            measured += 1
            marks = []
            for line in out.read_text().splitlines():
                name, _, cpu = line.rpartition("\t")
                marks.append((name, float(cpu)))
            for name, value in buckets(marks, children).items():
                found.setdefault(name, []).append(value)
    return found


def table(found: dict[str, list[float]]) -> str:
    lines = [f"{'bucket':52s} {'CPU min':>9s} {'median':>9s}"]
    for name, values in found.items():
        lines.append(
            f"{name:52s} {min(values) * 1000:7.2f} ms {statistics.median(values) * 1000:6.2f} ms"
        )
    return "\n".join(lines) + f"\n(load average {os.getloadavg()[0]:.2f})\n"


def main(args: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/startup_profile.py", description=__doc__)
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--tree", help="a checkout of mlaunch to run instead (put on PYTHONPATH)")
    parser.add_argument("--json", help="write the buckets' samples here")
    parser.add_argument(
        "--children",
        type=int,
        default=1,
        help="profile until the N-th child was started (the launch's first N), not the first",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="profile a repeated start's quick start (the plan cache on; the first run writes"
        " the entry: give a launch file settled for two seconds)",
    )
    parser.add_argument("command", nargs=argparse.REMAINDER)
    opts = parser.parse_args(args)
    command = [c for c in opts.command if c != "--"] if opts.command[:1] == ["--"] else opts.command
    if not command:
        parser.error("give the mlaunch command to run after --")
    # As benchmarks/run.py measures: bytecode written and read, buffered output.
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONUNBUFFERED")
    }
    found = profile(command, env, opts.runs, opts.tree, opts.children, opts.quick)
    sys.stdout.write(table(found))
    if opts.json:
        Path(opts.json).write_text(json.dumps(found, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
