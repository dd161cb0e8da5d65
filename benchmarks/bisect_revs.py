"""Which commit made start-up slower: several revisions of mlaunch side by side, in one run.

    .venv/bin/python benchmarks/bisect_revs.py [--runs N] [--n 100] [--format py|yaml|xml]
                                               [--ros2] [--floor] [--calls] [--cache]
                                               [--json FILE] REV ...
    .venv/bin/python benchmarks/bisect_revs.py --between OLD NEW --steps K [...]

Each revision is checked out into a temporary worktree (``git worktree add --detach``, removed
at the end) and run by this interpreter with ``PYTHONPATH`` at that tree, so nothing is
reinstalled: the venv's packages are shared, only mlaunch's code differs. Every revision is
started as the ``mlaunch`` command scripts/setup writes starts it (the ROS wheels' hook's
environment given, no re-exec), on the same generated launch of N children (``ready_child.sh``,
as ``run.py``'s); the rounds alternate the revisions (rotating the order each round, so a burst
of load from elsewhere hits them all) and the table gives best and median over the rounds of:

- CPU ms: user + system time of the launcher, read the moment the N-th child reports running:
  mlaunch and every descendant running the same executable (its guard, a fork), each thread to
  the nanosecond from ``schedstat`` plus the ticks of threads that already ended. On a shared
  machine this is the figure to compare: it does not grow while the launcher waits for a core.
- all ms: wall time from exec of the launcher to the N-th child running (confirms the CPU);
- first ms: to the first child running.

``--calls`` adds one run of each revision that counts the Python calls (and C calls made from
Python) until the first and the N-th child were started, and the modules loaded by then: the
same on an idle or a loaded machine, so one run says what a change costs. The plan cache is
off (``MLAUNCH_NO_CACHE=1``) unless ``--cache``: revisions before it always resolve the file.
``--floor`` adds the bare Popen loop (``floor_spawn.py``, started as the revisions are) as a
column, and each revision's ratios to it: the figure of "within 1.1x of the floor" that a
loaded machine does not blur. ``--ros2`` adds the reference ros2 launch (found as ``run.py``
finds it) as one more column of the same rounds, and the ratios of each revision to it. ``--between OLD NEW --steps K`` measures
K+1 revisions evenly spread over OLD..NEW's first-parent history (both ends included): bisect by
narrowing it run after run.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
VENV = Path(sys.prefix)  # the interpreter's venv: its ROS wheels' hook is given its environment
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

import launchgen as gen  # noqa: E402
import probes as pr  # noqa: E402
import run as bench  # noqa: E402
from probes import BenchError  # noqa: E402

# What the mlaunch command scripts/setup writes runs (site without the ROS wheels' hook, whose
# environment the harness gives), the same for every revision. With MLAUNCH_BISECT_CALLS=FILE it
# also counts the Python calls (and C calls from Python) until the first and the N-th child were
# started, and the modules loaded by then: figures that do not depend on the machine's load.
LAUNCHER = """\
import sys
sys.modules.setdefault("ros_wheels_bootstrapper", type(sys)("ros_wheels_bootstrapper"))
import site
site.main()
import os
if os.environ.get("MLAUNCH_BISECT_CALLS"):
    import subprocess
    out, want, calls, marks = os.environ.pop("MLAUNCH_BISECT_CALLS"), {n}, [0], []
    def count(frame, event, arg):
        if event == "call" or event == "c_call":
            calls[0] += 1
    def counting(start):
        def counted(*args, **kwargs):
            marks.append(calls[0])
            pid = start(*args, **kwargs)
            if len(marks) == want:
                sys.setprofile(None)
                with open(out, "w") as f:
                    f.write(f"{{marks[0]}} {{calls[0]}} {{len(sys.modules)}}\\n")
            return pid
        return counted
    try:  # revisions that start children with engine.spawning (Popen only as a fallback)
        from mlaunch.engine import spawning
    except ImportError:
        spawning = None
    if spawning is not None and spawning.AVAILABLE:
        spawning.start = counting(spawning.start)
    else:
        subprocess.Popen.__init__ = counting(subprocess.Popen.__init__)
    sys.setprofile(count)
from mlaunch.cli import program
program()
"""

# The floor (benchmarks/floor_spawn.py: a bare Popen loop) run as the revisions are run.
FLOOR = """\
import sys
sys.modules.setdefault("ros_wheels_bootstrapper", type(sys)("ros_wheels_bootstrapper"))
import site
site.main()
sys.path.insert(0, {here!r})
import floor_spawn
sys.exit(floor_spawn.main(sys.argv[1:]))
"""


@dataclass
class Subject:
    """One column of the rounds: a revision of mlaunch, or the reference ros2 launch."""

    label: str
    argv: list[str]
    env: dict[str, str]
    about: str
    # SIGINT and wait for a clean exit after each run (ros2 launch needs tens of seconds to
    # stop 100 children: it is killed, with its process group and every descendant, instead).
    graceful: bool = True
    samples: list[dict[str, float]] = field(default_factory=list)
    # Python calls until the first and the N-th child were started, modules loaded by then.
    calls: tuple[int, int, int] | None = None

    def best(self, key: str) -> float:
        return min(s[key] for s in self.samples)

    def median(self, key: str) -> float:
        return statistics.median(s[key] for s in self.samples)


def git(*args: str) -> str:
    done = subprocess.run(
        ["git", "-C", str(REPO), *args], capture_output=True, text=True, check=True
    )
    return done.stdout.strip()


def spread(old: str, new: str, steps: int) -> list[str]:
    """steps+1 commits evenly spaced over old..new (first parent), old and new included."""
    history = git("rev-list", "--first-parent", "--reverse", f"{old}..{new}").split()
    chain = [git("rev-parse", old), *history]
    if steps <= 0 or len(chain) <= steps + 1:
        return chain
    picks = [chain[round(i * (len(chain) - 1) / steps)] for i in range(steps + 1)]
    return list(dict.fromkeys(picks))


# --- one run ---------------------------------------------------------------------------------


def one_run(subject: Subject, n: int, fifo: Path, out_file: Path) -> dict[str, float]:
    probe = pr.ReadyProbe(fifo).open()
    with open(out_file, "wb") as out:
        proc = pr.launch(subject.argv, subject.env, stdout=out.fileno(), stderr=subprocess.STDOUT)
    try:
        try:
            first, last = probe.wait_ready(n, proc, time.perf_counter() + 30 + n / 10)
            cpu = pr.launcher_cpu(proc.pid)
            if subject.graceful:
                pr.stop_and_time(proc, probe, signal.SIGINT, 30.0)
        except BenchError as e:
            tail = bench.one_line(out_file.read_text(errors="replace"))
            raise BenchError(f"{subject.label}: {e}; output: {tail}") from None
        return {"cpu": cpu, "all": last - proc.started, "first": first - proc.started}
    finally:
        proc.kill()
        probe.close()
        pr.kill_descendants()


# --- the subjects ----------------------------------------------------------------------------


def revision_subject(rev: str, trees: Path, env: dict[str, str], argv: list[str]) -> Subject:
    sha = git("rev-parse", "--verify", f"{rev}^{{commit}}")
    tree = trees / sha[:10]
    if not tree.exists():
        git("worktree", "add", "--detach", "--quiet", str(tree), sha)
    subject_env = {**env, "PYTHONPATH": str(tree)}
    title = git("log", "-1", "--format=%s", sha)
    return Subject(sha[:7], argv, subject_env, title)


def reference_subject(env: dict[str, str], launch: Path) -> Subject:
    """ros2 launch as a user runs it (run.py's: env.sh sourced once, then ``ros2 launch``)."""
    found = bench.find_reference(env)
    if isinstance(found, str):
        raise SystemExit(f"bisect_revs: --ros2: {found}")
    return Subject("ros2", found.argv(launch), found.env, found.about, graceful=False)


# --- the table -------------------------------------------------------------------------------


def table(subjects: Sequence[Subject], ref: Subject | None, meta: dict[str, object]) -> str:
    lines = [
        f"N={meta['n']} children ({meta['format']}), {meta['runs']} rounds after a warm-up;"
        f" load average {meta['load_before']} -> {meta['load_after']}",
        "",
    ]
    head = f"{'rev':8} {'CPU ms best/med':>16} {'all ms best/med':>16} {'first ms':>9}"
    counted = any(s.calls for s in subjects)
    if counted:
        head += f" {'calls first/all':>16} {'modules':>7}"
    floor = next((s for s in subjects if s.label == "floor"), None)
    if floor is not None:
        head += f" {'CPU/floor':>9} {'all/floor':>9}"
    if ref is not None:
        head += f" {'CPU/ros2':>9} {'all/ros2':>9}"
    lines.append(head + "  subject")
    for s in [*subjects, ref] if ref is not None else subjects:
        row = (
            f"{s.label:8} {s.best('cpu') * 1e3:7.1f}/{s.median('cpu') * 1e3:7.1f}"
            f"  {s.best('all') * 1e3:7.1f}/{s.median('all') * 1e3:7.1f}"
            f" {s.best('first') * 1e3:9.1f}"
        )
        if counted:
            first, every, modules = s.calls or (0, 0, 0)
            row += f" {first:7d}/{every:8d} {modules:7d}" if s.calls else " " * 25
        if floor is not None:
            row += (
                f" {s.median('cpu') / floor.median('cpu'):9.3f}"
                f" {s.median('all') / floor.median('all'):9.3f}"
            )
        if ref is not None:
            row += (
                f" {s.median('cpu') / ref.median('cpu'):9.3f}"
                f" {s.median('all') / ref.median('all'):9.3f}"
            )
        lines.append(row + "  " + s.about[:70])
    return "\n".join(lines) + "\n"


def parse_args(argv: Sequence[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="bisect_revs.py", description=__doc__.split("\n\n")[0])
    p.add_argument("revs", nargs="*", help="revisions to compare (any git revision)")
    p.add_argument("--between", nargs=2, metavar=("OLD", "NEW"))
    p.add_argument("--steps", type=int, default=8, help="with --between: K+1 revisions")
    p.add_argument("--runs", type=int, default=7, help="rounds after the warm-up (7)")
    p.add_argument("--n", type=int, default=100, help="children in the launch (100)")
    p.add_argument("--format", choices=gen.FORMATS, default="py")
    p.add_argument("--ros2", action="store_true", help="add the reference ros2 launch")
    p.add_argument(
        "--floor",
        action="store_true",
        help="add the bare Popen loop (floor_spawn.py, run as the revisions are) and the ratios"
        " to it",
    )
    p.add_argument(
        "--cache",
        action="store_true",
        help="let revisions that have the plan cache use it (off: MLAUNCH_NO_CACHE=1, so every"
        " revision loads and resolves the file, as those before the cache did)",
    )
    p.add_argument(
        "--calls",
        action="store_true",
        help="one more run of each revision counting Python calls to the first and N-th child",
    )
    p.add_argument("--json", help="also write the samples as JSON to FILE")
    args = p.parse_args(argv)
    if not args.revs and not args.between:
        p.error("name revisions, or --between OLD NEW")
    return args


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)  # the children stop on SIGINT
    revs = list(args.revs)
    if args.between:
        revs += spread(args.between[0], args.between[1], args.steps)
    pr.become_subreaper()
    tmp = Path(tempfile.mkdtemp(prefix="mlaunch-bisect-"))
    trees = tmp / "trees"
    trees.mkdir()
    try:
        env = bench.measured_env(dict(os.environ), tmp / "logs")
        env["XDG_CACHE_HOME"] = str(tmp / "cache")  # a plan cache of this run's own
        mlaunch_env = {**env, **bench.merge_ld_path(bench.hook_finished_env(VENV), env)}
        if not args.cache:
            mlaunch_env["MLAUNCH_NO_CACHE"] = "1"
        scripts = gen.write_child_scripts(tmp / "bin")
        fifo, out_file = tmp / "ready.fifo", tmp / "out.txt"
        child = [str(scripts.ready), str(fifo)]
        launch = gen.write(
            [gen.many_children(f"start_{args.n}", args.n, child)], args.format, tmp / "launch"
        )
        argv = [sys.executable, "-S", "-P", "-c", LAUNCHER.format(n=args.n), str(launch)]
        subjects = [revision_subject(rev, trees, mlaunch_env, argv) for rev in dict.fromkeys(revs)]
        if args.floor:
            floor_argv = [sys.executable, "-S", "-P", "-c", FLOOR.format(here=str(HERE))]
            floor_argv += [str(args.n), *child]
            about = "bare Popen loop (benchmarks/floor_spawn.py)"
            subjects.append(Subject("floor", floor_argv, mlaunch_env, about))
        ref = None
        if args.ros2:
            with bench.ros_domain(None) as domain:
                ref = reference_subject({**env, "ROS_DOMAIN_ID": str(domain)}, launch)
                return measure(args, [*subjects, ref], subjects, ref, fifo, out_file)
        return measure(args, subjects, subjects, ref, fifo, out_file)
    finally:
        pr.kill_descendants()
        for tree in trees.iterdir():
            subprocess.run(
                ["git", "-C", str(REPO), "worktree", "remove", "--force", str(tree)],
                capture_output=True,
            )
        subprocess.run(["git", "-C", str(REPO), "worktree", "prune"], capture_output=True)
        subprocess.run(["rm", "-rf", str(tmp)], check=False)


def measure(
    args: argparse.Namespace,
    columns: list[Subject],
    revisions: list[Subject],
    ref: Subject | None,
    fifo: Path,
    out_file: Path,
) -> int:
    load_before = [round(x, 2) for x in os.getloadavg()]
    for round_no in range(args.runs + 1):  # round 0 warms up (bytecode, caches)
        shift = round_no % len(columns)
        for subject in columns[shift:] + columns[:shift]:
            one = one_run(subject, args.n, fifo, out_file)
            if round_no:
                subject.samples.append(one)
        print(f"round {round_no}/{args.runs} done", file=sys.stderr, flush=True)
    if args.calls:
        counts = out_file.with_name("calls.txt")
        for subject in revisions:
            if subject.label == "floor":
                continue  # counts mlaunch's calls only
            counting = Subject(subject.label, subject.argv, subject.env, subject.about)
            counting.env = {**subject.env, "MLAUNCH_BISECT_CALLS": str(counts)}
            one_run(counting, args.n, fifo, out_file)
            first, every, modules = (int(x) for x in counts.read_text().split())
            subject.calls = (first, every, modules)
            counts.unlink()
    meta: dict[str, object] = {
        "n": args.n,
        "format": args.format,
        "runs": args.runs,
        "load_before": load_before,
        "load_after": [round(x, 2) for x in os.getloadavg()],
        "python": sys.executable,
        "plan_cache": args.cache,
    }
    sys.stdout.write(table(revisions, ref, meta))
    if args.json:
        document = {
            "meta": meta,
            "subjects": [
                {"label": s.label, "about": s.about, "samples": s.samples, "calls": s.calls}
                for s in ([*revisions, ref] if ref else revisions)
            ],
        }
        Path(args.json).write_text(json.dumps(document, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
