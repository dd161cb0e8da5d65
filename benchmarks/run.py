"""mlaunch benchmarks: each figure beside its floor, measured in the same run.

    .venv/bin/python benchmarks/run.py [--quick] [--json FILE|-] [--venv ros|plain|both]
                                       [--only startup,print,output,sim,importtime] [--runs N]

Prints a table (min and median over the runs, the floor's min and median, the ratio of the
medians, and the target with PASS/MISS judged on the median) and writes the same as JSON
(default: benchmarks/results/<mode>-<time>.json). Targets are printed, never asserted.

mlaunch is measured in two interpreters: the project venv (with the ROS wheels' .pth hook that
re-execs every interpreter once) and a plain venv without the ros extra, created on first use in
benchmarks/.cache/venv-plain. Each is compared with floors run by the same interpreter.
See benchmarks/README.md for what is measured and how.
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import json
import os
import platform
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

sys.path.append(str(REPO / "tests"))  # the ROS-domain lock the tests take (tests/ros_domain.py)
import launchgen as gen  # noqa: E402
import probes as pr  # noqa: E402
import startup_profile  # noqa: E402
from probes import BenchError  # noqa: E402
from reference import HOME as REFERENCE_HOME  # noqa: E402
from reference import MISSING as REFERENCE_MISSING  # noqa: E402
from ros_domain import private_domain  # noqa: E402

GROUPS = (
    "startup",
    "print",
    "output",
    "memory",
    "sim",
    "importtime",
    "profile",
    "plancache",
    "autoware",
    "fleet",
)  # --only
# Minutes long, and needing what a run does not always have (sources fetched beforehand;
# ansible-core and sshd for fleet, a deploy over private sshd daemons, tests/fleet.py), or a
# figure of its own (plancache: cold against warm resolves, Autoware's too when its sources are
# there): only when --only names them.
OPT_IN_GROUPS = ("plancache", "autoware", "fleet")
DEFAULT_GROUPS = tuple(g for g in GROUPS if g not in OPT_IN_GROUPS)
# The table's sections: shutdown and memory are measured in the start-up runs.
SECTIONS = (
    "startup",
    "profile",
    "shutdown",
    "memory",
    "print",
    "plancache",
    "output",
    "sim",
    "autoware",
    "fleet",
)
SIM_LAUNCH = REPO / "launches" / "jtbot_sim.launch.py"
SIM_WORLD = REPO / "robots" / "jtbot_description" / "world" / "jt.world"
SIM_XACRO = REPO / "robots" / "jtbot_description" / "urdf" / "jtbot.urdf.xacro"
PLAIN_VENV = HERE / ".cache" / "venv-plain"


@dataclass(frozen=True)
class Config:
    """How much to measure: quick mode proves the harness works, full mode gives the figures."""

    mode: str
    runs: int
    startup_ns: tuple[int, ...]
    shutdown_ns: tuple[int, ...]
    memory_n: int
    idle_seconds: float
    output_procs: int
    output_lines: int
    sim_runs: int
    sim_seconds: float
    # ros2 launch passes ~30k lines/s at best: its output runs print fewer lines a child (the
    # figure is a rate, so comparable), or one run would take half a minute.
    reference_output_lines: int


QUICK = Config("quick", 2, (1, 10, 100), (10, 100), 100, 1.0, 4, 100_000, 1, 2.0, 5_000)
FULL = Config("full", 5, (1, 10, 100, 500), (10, 100, 500), 100, 2.0, 4, 250_000, 2, 5.0, 25_000)
# The start-up sizes (Python files) ros2 launch is measured at beside mlaunch: its 500 children
# take seconds a run and add nothing the 100 do not show.
REFERENCE_NS = (1, 100)
REFERENCE_TRIES = 3  # per run: see Bench.reference_turn


@dataclass(frozen=True)
class Venv:
    """An interpreter mlaunch is measured in."""

    name: str
    python: Path
    mlaunch: Path
    about: str
    # What the ROS wheels' .pth hook would re-exec Python for (their libraries on
    # LD_LIBRARY_PATH, its guard), as the mlaunch command scripts/setup writes gives it to
    # Python at its first exec: the floors get it too, so both skip the re-exec alike.
    finished_env: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Reference:
    """The reference ros2 launch (Jazzy's launch 3.4.3 and launch_ros 0.26.6, built by
    scripts/reference): run as a user who sourced its env.sh runs ``ros2 launch FILE``."""

    ros2: Path
    env: dict[str, str]
    about: str

    def argv(self, path: Path) -> list[str]:
        return [str(self.ros2), "launch", str(path)]


@dataclass(frozen=True)
class Target:
    """A goal a median is judged against (printed as PASS/MISS, never asserted)."""

    limit: float
    higher_is_better: bool = False

    def status(self, value: float) -> str:
        ok = value >= self.limit if self.higher_is_better else value <= self.limit
        return "PASS" if ok else "MISS"

    def text(self, unit: str) -> str:
        return ("≥ " if self.higher_is_better else "≤ ") + fmt_value(self.limit, unit)


@dataclass
class Row:
    """One measured figure: mlaunch's samples and its floor's, from the same run."""

    group: str
    name: str
    venv: str
    unit: str
    samples: list[float]
    floor_name: str = ""
    floor_samples: list[float] = field(default_factory=list)
    target: Target | None = None
    params: dict[str, Any] = field(default_factory=dict)
    note: str = ""
    reference_samples: list[float] = field(default_factory=list)  # ros2 launch's, same run

    @property
    def median(self) -> float:
        return statistics.median(self.samples)

    @property
    def best(self) -> float:
        """The best sample: the minimum, or the maximum for rates."""
        return max(self.samples) if self.unit == "lines/s" else min(self.samples)

    @property
    def floor_median(self) -> float | None:
        return statistics.median(self.floor_samples) if self.floor_samples else None

    @property
    def ratio(self) -> float | None:
        return self._ratio(self.floor_median)

    @property
    def reference_median(self) -> float | None:
        return statistics.median(self.reference_samples) if self.reference_samples else None

    @property
    def reference_ratio(self) -> float | None:
        """mlaunch's median over ros2 launch's (below 1: mlaunch takes less; rates: more)."""
        return self._ratio(self.reference_median)

    def _ratio(self, other: float | None) -> float | None:
        if other is None or other == 0 or self.unit == "lines":
            return None
        return self.median / other

    def _series(self, name: str, samples: list[float]) -> dict[str, Any] | None:
        if not samples:
            return None
        return {
            "name": name,
            "best": best_of(samples, self.unit),
            "median": statistics.median(samples),
            "samples": samples,
        }

    def to_json(self) -> dict[str, Any]:
        target = None
        if self.target is not None:
            target = {
                "limit": self.target.limit,
                "op": ">=" if self.target.higher_is_better else "<=",
                "status": self.target.status(self.median),
            }
        return {
            "group": self.group,
            "name": self.name,
            "venv": self.venv,
            "unit": self.unit,
            "params": self.params,
            "mlaunch": {"best": self.best, "median": self.median, "samples": self.samples},
            "floor": self._series(self.floor_name, self.floor_samples),
            "ratio": self.ratio,
            "reference": self._series("ros2 launch", self.reference_samples),
            "reference_ratio": self.reference_ratio,
            "target": target,
            "note": self.note,
        }


@dataclass
class Skip:
    """A figure that could not be measured, and why."""

    group: str
    venv: str
    what: str
    reason: str


@dataclass
class Results:
    rows: list[Row] = field(default_factory=list)
    skips: list[Skip] = field(default_factory=list)
    importtime: dict[str, dict[str, Any]] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)

    def skip(self, group: str, venv: str, what: str, reason: str) -> None:
        self.skips.append(Skip(group, venv, what, one_line(reason)))

    def to_json(self) -> dict[str, Any]:
        return {
            "meta": self.meta,
            "rows": [r.to_json() for r in self.rows],
            "skipped": [asdict(s) for s in self.skips],
            "importtime": self.importtime,
        }


def best_of(samples: Sequence[float], unit: str) -> float:
    return max(samples) if unit == "lines/s" else min(samples)


def one_line(text: str, limit: int = 240) -> str:
    lines = [line.strip() for line in str(text).strip().splitlines() if line.strip()]
    line = lines[-1] if lines else ""
    return line if len(line) <= limit else line[: limit - 3] + "..."


# --- environment ----------------------------------------------------------------------------


def measured_env(base: dict[str, str], log_dir: Path) -> dict[str, str]:
    """The environment of every measured command: a user's shell, as far as it can be rebuilt.

    PYTHONUNBUFFERED / PYTHONDONTWRITEBYTECODE are cleared. So is what the ROS wheels' hook put
    into the harness's own environment when it re-exec'd it (the guard variable and its
    LD_LIBRARY_PATH entries): each measured interpreter of the project venv then pays the hook
    as it does when a user starts it. ROS_LOG_DIR keeps mlaunch's log files in the harness's
    temp dir instead of ~/.ros/log (the cost of writing them is the same).
    """
    env = dict(base)
    for name in ("PYTHONUNBUFFERED", "PYTHONDONTWRITEBYTECODE", "_ROS_WHEELS_BOOTSTRAP_COMPLETE"):
        env.pop(name, None)
    prefix = str(REPO / ".venv")
    kept = [p for p in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p]
    kept = [p for p in kept if not os.path.realpath(p).startswith(os.path.realpath(prefix))]
    if kept:
        env["LD_LIBRARY_PATH"] = os.pathsep.join(kept)
    else:
        env.pop("LD_LIBRARY_PATH", None)
    env["ROS_LOG_DIR"] = str(log_dir)
    # Every figure but the plancache group's is of a launch loaded and resolved: repeated runs
    # of one file would otherwise take the plan from the cache (docs/plan-cache.md).
    env["MLAUNCH_NO_CACHE"] = "1"
    return env


def merge_ld_path(finished: dict[str, str], env: dict[str, str]) -> dict[str, str]:
    """``finished`` with the user's LD_LIBRARY_PATH after its own (as the hook keeps it)."""
    if not finished:
        return {}
    own = env.get("LD_LIBRARY_PATH")
    ld = finished["LD_LIBRARY_PATH"] + (os.pathsep + own if own else "")
    return {**finished, "LD_LIBRARY_PATH": ld}


def project_venv() -> Venv | str:
    python = REPO / ".venv" / "bin" / "python"
    mlaunch = REPO / ".venv" / "bin" / "mlaunch"
    if not mlaunch.exists():
        return f"{mlaunch} does not exist (pip install -e '.[ros,dev]' into {REPO / '.venv'})"
    about = "project venv (.venv, ROS wheels' re-exec hook)"
    return Venv("ros", python, mlaunch, about, hook_finished_env(REPO / ".venv"))


def hook_finished_env(venv: Path) -> dict[str, str]:
    """The variables the ROS wheels' hook sets before its re-exec ({} without the hook)."""
    found = sorted((venv / "lib").glob("python3*/site-packages/ros_wheels_bootstrapper.pth"))
    if not found:
        return {}
    libs = [str(p.resolve()) for p in sorted(found[0].parent.glob("ros_*.libs")) if p.is_dir()]
    return {
        "LD_LIBRARY_PATH": os.pathsep.join([str(venv / "lib"), *libs]),
        "_ROS_WHEELS_BOOTSTRAP_COMPLETE": "1",
    }


def plain_venv() -> Venv | str:
    """The plain venv (no ros extra), created or refreshed when pyproject.toml changed."""
    python, mlaunch = PLAIN_VENV / "bin" / "python", PLAIN_VENV / "bin" / "mlaunch"
    stamp_file = PLAIN_VENV / ".bench-stamp"
    # The install mode is part of the stamp: an older venv made with the default editable mode
    # (an import hook costing ~12-15 ms a start) is rebuilt.
    stamp = hashlib.sha256((REPO / "pyproject.toml").read_bytes() + b"compat").hexdigest()
    about = "plain venv (benchmarks/.cache/venv-plain, core deps only)"
    if mlaunch.exists() and stamp_file.exists() and stamp_file.read_text() == stamp:
        return Venv("plain", python, mlaunch, about)
    base = getattr(sys, "_base_executable", sys.executable)
    print(f"creating {PLAIN_VENV} with {base} (once) ...", file=sys.stderr, flush=True)
    shutil.rmtree(PLAIN_VENV, ignore_errors=True)
    steps = [
        [base, "-m", "venv", str(PLAIN_VENV)],
        # compat mode: a path entry, as scripts/setup installs it, not setuptools' import hook.
        [
            str(python),
            "-m",
            "pip",
            "install",
            "-q",
            "--disable-pip-version-check",
            "-e",
            str(REPO),
            "--config-settings",
            "editable_mode=compat",
        ],
    ]
    env = {k: v for k, v in os.environ.items() if k != "_ROS_WHEELS_BOOTSTRAP_COMPLETE"}
    for step in steps:
        done = subprocess.run(step, capture_output=True, text=True, env=env, timeout=600)
        if done.returncode != 0:
            errors = [line for line in done.stderr.splitlines() if "is ignored" not in line]
            return f"cannot create the plain venv: {' '.join(step[:4])}: {one_line(chr(10).join(errors))}"
    stamp_file.write_text(stamp)
    return Venv("plain", python, mlaunch, about)


def find_reference(env: dict[str, str]) -> Reference | str:
    """The reference ros2 launch where tests/reference.py finds it, with the environment its
    env.sh gives on top of ``env``; else why not (printed as a skip, its rows go without it)."""
    env_sh = REFERENCE_HOME / "env.sh"
    if not env_sh.exists():
        return REFERENCE_MISSING
    # Sourced once here, not per run: each measured start is the ros2 executable itself, as
    # from a shell where the user sourced env.sh (as /opt/ros/jazzy/setup.bash) beforehand.
    done = subprocess.run(
        ["bash", "-c", 'source "$1" >/dev/null && env -0', "bash", str(env_sh)],
        env=env,
        capture_output=True,
        timeout=60,
    )
    if done.returncode != 0:
        return f"sourcing {env_sh} failed: {one_line(done.stderr.decode(errors='replace'))}"
    sourced = dict(item.split("=", 1) for item in done.stdout.decode().split("\0") if "=" in item)
    for name in ("_", "SHLVL", "PWD", "OLDPWD"):
        sourced.pop(name, None)
        if name in env:
            sourced[name] = env[name]
    ros2 = shutil.which("ros2", path=sourced.get("PATH"))
    if ros2 is None:
        return f"no ros2 executable on the PATH {env_sh} sets"
    return Reference(Path(ros2), sourced, f"ros2 launch of {REFERENCE_HOME} (env.sh sourced)")


@contextmanager
def ros_domain(requested: int | None) -> Iterator[int]:
    """A ROS_DOMAIN_ID no test or other benchmark holds (tests/ros_domain.py: the one lock)."""
    if requested is not None:
        yield requested
        return
    with private_domain() as domain:
        yield domain


# --- the harness ----------------------------------------------------------------------------


class Bench:
    """Runs the cases for each venv and collects Rows; every case cleans up after itself."""

    def __init__(
        self,
        config: Config,
        venvs: list[Venv],
        tmp: Path,
        results: Results,
        reference: bool = True,
    ) -> None:
        self.config = config
        self.venvs = venvs
        self.tmp = tmp
        self.results = results
        self.logs = tmp / "logs"
        self.env = measured_env(dict(os.environ), self.logs)
        # ros2 launch beside mlaunch: measured once, alternating with the first venv's runs,
        # and shown in every venv's rows (it runs in its own venv either way).
        self.reference: Reference | None = None
        if reference:
            found = find_reference(self.env)
            if isinstance(found, str):
                results.skip("all", "ros2 launch", "the ros2 launch column", found)
            else:
                self.reference = found
                results.meta["reference"] = found.about
        self.reference_runs: dict[str, list[dict[str, float]]] = {}
        self.reference_failed: set[str] = set()
        self.scripts = gen.write_child_scripts(tmp / "bin")
        self.fifo = tmp / "ready.fifo"
        self.launches = tmp / "launches"
        self.out_file = tmp / "out.txt"
        self.interpreter: dict[str, list[float]] = {}
        self.formats = self._formats()

    def _formats(self) -> list[str]:
        """The launch formats mlaunch has a frontend for right now (others are skipped)."""
        found = ["py"]
        for fmt, module in (("yaml", "yaml.py"), ("xml", "xml.py")):
            if (REPO / "mlaunch" / "frontends" / module).exists():
                found.append(fmt)
            else:
                self.results.skip(
                    "startup",
                    "all",
                    f"{fmt} rows",
                    f"mlaunch/frontends/{module} is not there yet (the files are generated)",
                )
        return found

    # --- helpers -------------------------------------------------------------------------

    def runs(self) -> range:
        """Run 0 is the warm-up (bytecode compiled, caches warm) and is not counted."""
        return range(self.config.runs + 1)

    def wall(
        self, argv: Sequence[str], timeout: float = 60.0, env: dict[str, str] | None = None
    ) -> float:
        """Seconds from exec of ``argv`` to its exit; BenchError with its output if it fails."""
        with open(self.out_file, "wb") as out:
            proc = pr.launch(
                argv,
                self.env if env is None else env,
                stdout=out.fileno(),
                stderr=subprocess.STDOUT,
            )
        try:
            code = proc.reap(time.perf_counter() + timeout)
        finally:
            proc.kill()
        if code != 0:
            raise BenchError(f"exit {code}: {self.output_tail()}")
        assert proc.exited_at is not None
        return proc.exited_at - proc.started

    def reference_turn(
        self, group: str, key: str, i: int, measure: Callable[[Reference], dict[str, float]]
    ) -> None:
        """ros2 launch's run ``i`` of ``key``, right after mlaunch's (until it has them all).

        On a loaded machine ros2 launch sometimes hangs at Ctrl-C (an exception in its process
        start, then it never sees that child's exit): such a run is tried again, up to
        REFERENCE_TRIES times, each failure listed (``meta.reference_retries``, the table's
        notes). Failing every try skips that figure's ros2 launch column, never mlaunch's row.
        """
        if self.reference is None or key in self.reference_failed:
            return
        got = self.reference_runs.setdefault(key, [])
        if len(got) >= self.config.runs:
            return
        for _ in range(REFERENCE_TRIES):
            try:
                one = measure(self.reference)
                break
            except BenchError as e:
                retries = self.results.meta.setdefault("reference_retries", [])
                retries.append({"group": group, "figure": key, "reason": one_line(str(e))})
        else:
            self.reference_failed.add(key)
            del self.reference_runs[key]
            self.results.skip(group, "ros2 launch", key, f"{REFERENCE_TRIES} tries failed")
            return
        if i:
            got.append(one)

    def reference_samples(self, key: str) -> list[dict[str, float]]:
        return self.reference_runs.get(key, [])

    def wait_output(self, line: bytes, n: int, proc: pr.Launched, deadline: float) -> None:
        """Until ``line`` is in the launcher's output ``n`` times (after the figures are taken)."""
        while self.out_file.read_bytes().count(line) < n:
            if proc.poll_exit():
                raise BenchError(f"exit {proc.returncode}: {self.output_tail()}")
            if time.perf_counter() > deadline:
                raise BenchError(f"{line.decode()!r} not {n} times in the output in time")
            time.sleep(0.002)

    def output_tail(self) -> str:
        try:
            return one_line(self.out_file.read_text(errors="replace"))
        except OSError:
            return ""

    def floor_env(self, venv: Venv) -> dict[str, str]:
        """The floors' environment: a user's shell, with what the hook would add given first."""
        return {**self.env, **merge_ld_path(venv.finished_env, self.env)}

    def interpreter_floor(self, venv: Venv) -> list[float]:
        """``python -c pass`` in this venv (measured once, used as the floor of several rows);
        where the ROS wheels' hook re-execs it, both ways (the floor: with the hook skipped)."""
        if venv.name not in self.interpreter:
            argv = [str(venv.python), "-c", "pass"]
            hooked: list[float] = []
            skipped: list[float] = []
            for i in self.runs():  # alternating
                one = self.wall(argv)
                two = self.wall(argv, env=self.floor_env(venv)) if venv.finished_env else 0.0
                if i:
                    hooked.append(one)
                    skipped.append(two)
            self.results.rows.append(
                Row("startup", "python -c pass (exec to exit)", venv.name, "s", hooked)
            )
            self.interpreter[venv.name] = hooked
            if venv.finished_env:
                name = "python -c pass, hook's environment given (no re-exec)"
                self.results.rows.append(Row("startup", name, venv.name, "s", skipped))
                self.interpreter[venv.name] = skipped
        return self.interpreter[venv.name]

    def children_run(
        self,
        argv: Sequence[str],
        n: int,
        idle: float = 0.0,
        env: dict[str, str] | None = None,
        sigint_exit: int = 128 + signal.SIGINT,
        noted: bytes | None = None,
        stop_timeout: float = 20.0,
        stop_group: bool = False,
    ) -> dict[str, float]:
        """Start a launcher of N ready-children; time first/all running, idle CPU, RSS, stop.

        ``sigint_exit`` is the launcher's exit status after SIGINT (ros2 launch exits 0).
        ``noted``: before the idle window and the SIGINT, wait until the launcher's output holds
        this line N times (ros2 launch: a SIGINT before it has noted a start never reaches that
        child, and it waits for it forever). ``stop_group``: the SIGINT goes to the launcher's
        process group, as a terminal's Ctrl-C does (ros2 launch's children are in it; mlaunch's
        each have a session of their own, so it alone would get it either way).
        """
        probe = pr.ReadyProbe(self.fifo).open()
        with open(self.out_file, "wb") as out:
            proc = pr.launch(
                argv,
                self.env if env is None else env,
                stdout=out.fileno(),
                stderr=subprocess.STDOUT,
            )
        try:
            first, last = probe.wait_ready(n, proc, time.perf_counter() + 30 + n / 10)
            result = {"first": first - proc.started, "all": last - proc.started}
            if n == 1:
                # The launcher's CPU from its exec (the hook's re-exec included: same task) until
                # its child said it runs, read as the line arrives: what a loaded machine's
                # wall clock hides. The threads alive now only (a thread that ended is ~0).
                result["first_cpu"] = pr.fine_cpu_seconds(proc.pid)
            else:
                # The launcher's CPU (and its helpers' that run the same executable: mlaunch's
                # guard) until its N-th child said it runs: the figure to compare on a busy
                # machine, whose wall clock also measures the wait for a core.
                result["all_cpu"] = pr.launcher_cpu(proc.pid)
            if noted is not None:
                self.wait_output(noted, n, proc, time.perf_counter() + 30 + n / 10)
            if idle > 0:
                c0, t0 = pr.fine_cpu_seconds(proc.pid), time.perf_counter()
                time.sleep(idle)  # the measurement window itself, not a synchronisation
                c1, t1 = pr.fine_cpu_seconds(proc.pid), time.perf_counter()
                result["idle_cpu"] = (c1 - c0) / (t1 - t0)
            result["hwm"] = pr.vm_hwm_mb(proc.pid)
            result["shutdown"] = pr.stop_and_time(
                proc, probe, signal.SIGINT, stop_timeout, group=stop_group
            )
            if proc.returncode != sigint_exit:
                raise BenchError(f"exit {proc.returncode} after SIGINT: {self.output_tail()}")
            return result
        except BenchError as e:
            tail = self.output_tail()
            raise BenchError(f"{e}; output: {tail}" if tail else str(e))
        finally:
            proc.kill()
            probe.close()
            pr.kill_descendants()

    # --- start-up, shutdown, memory ---------------------------------------------------------

    def startup(self, venv: Venv) -> None:
        self.interpreter_floor(venv)  # a row of its own; the per-N floor is the bare Popen loop
        child = [str(self.scripts.ready), str(self.fifo)]
        floors: dict[int, list[dict[str, float]]] = {}
        for fmt in self.formats:
            for n in self.config.startup_ns:
                stem = f"start_{n}"
                path = gen.write(
                    [gen.many_children(stem, n, child)], fmt, self.launches / f"start_{fmt}"
                )
                floor_argv = [str(venv.python), str(HERE / "floor_spawn.py"), str(n), *child]
                idle = self.config.idle_seconds if (fmt, n) == ("py", self.config.memory_n) else 0
                samples: list[dict[str, float]] = []
                try:
                    for i in self.runs():
                        # The floor does not depend on the format: measured with the first.
                        if n not in floors or len(floors[n]) < i:
                            floor = self.children_run(floor_argv, n, idle, self.floor_env(venv))
                            if i:
                                floors.setdefault(n, []).append(floor)
                        one = self.children_run([str(venv.mlaunch), str(path)], n, idle)
                        if i:
                            samples.append(one)
                        if fmt == "py" and n in REFERENCE_NS:
                            measure = functools.partial(self._reference_children, path, n, idle)
                            self.reference_turn("startup", f"py N={n}", i, measure)
                except BenchError as e:
                    self.results.skip("startup", venv.name, f"{fmt} N={n}", str(e))
                    if n == self.config.startup_ns[0]:
                        break  # the frontend cannot run this format at all
                    continue
                refs = self.reference_samples(f"py N={n}") if fmt == "py" else []
                self._startup_rows(venv, fmt, n, samples, floors.get(n, []), refs)
                if fmt == "py" and n in REFERENCE_NS:
                    self.repeated_startup(venv, path, n, floor_argv, refs)
        self.node_startup(venv, floors.get(1, []))

    def repeated_startup(
        self,
        venv: Venv,
        path: Path,
        n: int,
        floor_argv: list[str],
        refs: list[dict[str, float]],
        *,
        kind: str = "py",
        more_env: dict[str, str] | None = None,
        inputs: Sequence[Path] = (),
    ) -> None:
        """A repeated start as a user has it: the plan cache on (a cache folder of the run's
        own), so the quick start (mlaunch.app.quick) starts the children; the floor again,
        alternating. Two runs first, not measured: the first resolves and stores the plan and
        the quick entry, the second is the first quick start (its bytecode written).
        ``kind``: the rows' name for the launch; ``inputs``: files it reads besides its own."""
        env = {**self.env, "XDG_CACHE_HOME": str(self.launches / "cache"), **(more_env or {})}
        env.pop("MLAUNCH_NO_CACHE", None)
        # An entry is written only for files settled two seconds (mlaunch.plan.inputs.RACY_NS).
        newest = max(p.stat().st_ctime for p in (path, path.parent, *inputs))
        time.sleep(max(0.0, newest + 2.2 - time.time()))
        samples: list[dict[str, float]] = []
        floors: list[dict[str, float]] = []
        try:
            self.children_run([str(venv.mlaunch), str(path)], n, 0, env)
            for i in self.runs():
                floor = self.children_run(floor_argv, n, 0, self.floor_env(venv))
                one = self.children_run([str(venv.mlaunch), str(path)], n, 0, env)
                if i:
                    floors.append(floor)
                    samples.append(one)
        except BenchError as e:
            self.results.skip("startup", venv.name, f"{kind} N={n} repeated", str(e))
            return
        params = {"format": "py", "n": n, "repeated": True, "kind": kind}
        key = "first" if n == 1 else "all"
        what = "first child running" if n == 1 else f"all {n} children running"
        rows = [(f"{what}, {kind}, repeated start (quick start)", key, "s")]
        if n == 1:
            rows.append(
                (f"CPU until the first child runs, {kind}, repeated start", "first_cpu", "s")
            )
        for name, field_name, unit in rows:
            self.results.rows.append(
                Row(
                    "startup",
                    name,
                    venv.name,
                    unit,
                    [s[field_name] for s in samples],
                    "bare Popen loop",
                    [f[field_name] for f in floors],
                    None,
                    params,
                    reference_samples=[r[field_name] for r in refs if field_name in r],
                )
            )

    def _reference_children(
        self, path: Path, n: int, idle: float, ref: Reference, prefix: Path | None = None
    ) -> dict[str, float]:
        env = ref.env
        if prefix is not None:
            paths = [str(prefix), *ref.env.get("AMENT_PREFIX_PATH", "").split(os.pathsep)]
            env = {**env, "AMENT_PREFIX_PATH": os.pathsep.join(p for p in paths if p)}
        # Unbuffered, so that its "process started" lines can be waited for (not timed).
        env = {**env, "PYTHONUNBUFFERED": "1"}
        return self.children_run(
            ref.argv(path),
            n,
            idle,
            env=env,
            sigint_exit=0,
            noted=b"process started with pid [",
            stop_timeout=30 + n,  # it ends its children one at a time: ~0.1 s each under load
            stop_group=True,
        )

    def node_startup(self, venv: Venv, floors: list[dict[str, float]]) -> None:
        """First child of a one-Node launch (an installed package, launch_ros's command line)."""
        path, prefix = gen.write_node_launch(self.launches / "node", self.scripts.ready, self.fifo)
        env = {**self.env, "AMENT_PREFIX_PATH": str(prefix)}
        samples: list[float] = []
        cpu: list[float] = []
        try:
            for i in self.runs():
                one = self.children_run([str(venv.mlaunch), str(path)], 1, env=env)
                if i:
                    samples.append(one["first"])
                    cpu.append(one["first_cpu"])
                measure = functools.partial(self._reference_children, path, 1, 0.0, prefix=prefix)
                self.reference_turn("startup", "py one Node", i, measure)
        except BenchError as e:
            self.results.skip("startup", venv.name, "py one Node", str(e))
            return
        self.repeated_startup(
            venv,
            path,
            1,
            [
                str(venv.python),
                str(HERE / "floor_spawn.py"),
                "1",
                str(self.scripts.ready),
                str(self.fifo),
            ],
            self.reference_samples("py one Node"),
            kind="py, one Node",
            more_env={"AMENT_PREFIX_PATH": str(prefix)},
            inputs=[p for p in prefix.rglob("*")],
        )
        self.results.rows.append(
            Row(
                "startup",
                "first child running, py, one Node",
                venv.name,
                "s",
                samples,
                "bare Popen loop",
                [f["first"] for f in floors],
                Target(0.06),
                {"format": "py", "n": 1, "node": True},
                reference_samples=[r["first"] for r in self.reference_samples("py one Node")],
            )
        )
        self.results.rows.append(
            Row(
                "startup",
                "CPU until the first child runs, py, one Node",
                venv.name,
                "s",
                cpu,
                "bare Popen loop",
                [f["first_cpu"] for f in floors],
                None,
                {"format": "py", "n": 1, "node": True},
                reference_samples=[r["first_cpu"] for r in self.reference_samples("py one Node")],
            )
        )

    def _startup_rows(
        self,
        venv: Venv,
        fmt: str,
        n: int,
        samples: list[dict[str, float]],
        floors: list[dict[str, float]],
        refs: list[dict[str, float]],
    ) -> None:
        def pick(runs: list[dict[str, float]], key: str) -> list[float]:
            return [r[key] for r in runs]

        def add(row: Row, key: str) -> None:
            """The row, with ros2 launch's figure of the same ``key`` where it was measured."""
            row.reference_samples = [r[key] for r in refs if key in r]
            self.results.rows.append(row)

        loop = "bare Popen loop"
        params = {"format": fmt, "n": n}
        first_target = Target(0.06) if (fmt, n) == ("py", 1) else None
        add(
            Row(
                "startup",
                f"first child running, {fmt}, N={n}",
                venv.name,
                "s",
                pick(samples, "first"),
                loop,
                pick(floors, "first"),
                first_target,
                params,
            ),
            "first",
        )
        if "first_cpu" in samples[0] and (not floors or "first_cpu" in floors[0]):
            add(
                Row(
                    "startup",
                    f"CPU until the first child runs, {fmt}, N={n}",
                    venv.name,
                    "s",
                    pick(samples, "first_cpu"),
                    loop,
                    pick(floors, "first_cpu"),
                    None,
                    params,
                ),
                "first_cpu",
            )
        if n > 1:
            targets = {100: Target(0.15), 500: Target(0.6)}
            add(
                Row(
                    "startup",
                    f"all {n} children running, {fmt}",
                    venv.name,
                    "s",
                    pick(samples, "all"),
                    loop,
                    pick(floors, "all"),
                    targets.get(n),
                    params,
                ),
                "all",
            )
            if "all_cpu" in samples[0] and (not floors or "all_cpu" in floors[0]):
                add(
                    Row(
                        "startup",
                        f"CPU until all {n} children run, {fmt}",
                        venv.name,
                        "s",
                        pick(samples, "all_cpu"),
                        loop,
                        pick(floors, "all_cpu"),
                        None,
                        params,
                    ),
                    "all_cpu",
                )
        if fmt != "py":
            return
        if n in self.config.shutdown_ns:
            add(
                Row(
                    "shutdown",
                    f"SIGINT until all gone, N={n}",
                    venv.name,
                    "s",
                    pick(samples, "shutdown"),
                    "bare loop: killpg + wait",
                    pick(floors, "shutdown"),
                    Target(0.15) if n == 100 else None,
                    params,
                ),
                "shutdown",
            )
        if n == self.config.memory_n or n == max(self.config.startup_ns):
            add(
                Row(
                    "memory",
                    f"peak RSS (VmHWM), {n} children",
                    venv.name,
                    "MB",
                    pick(samples, "hwm"),
                    loop,
                    pick(floors, "hwm"),
                    Target(30.0) if n == self.config.memory_n else None,
                    params,
                ),
                "hwm",
            )
        if "idle_cpu" in samples[0]:
            add(
                Row(
                    "memory",
                    f"idle CPU supervising {n} quiet children",
                    venv.name,
                    "cores",
                    pick(samples, "idle_cpu"),
                    loop,
                    pick(floors, "idle_cpu"),
                    None,
                    {**params, "window_s": self.config.idle_seconds},
                ),
                "idle_cpu",
            )

    # --- --show-args / --print ----------------------------------------------------------------

    def print_cases(self, venv: Venv) -> None:
        floor = self.interpreter_floor(venv)
        one = gen.write(
            [gen.many_children("one", 1, [str(self.scripts.ready), str(self.fifo)])],
            "py",
            self.launches / "one",
        )
        cases: list[tuple[str, Path]] = [("one-process launch, py", one)]
        for fmt in self.formats:
            top = gen.write(gen.big_system(), fmt, self.launches / f"big_{fmt}")
            cases.append((f"big synthetic launch, {fmt}", top))
        if SIM_LAUNCH.exists():
            cases.append(("launches/jtbot_sim.launch.py", SIM_LAUNCH))
        else:
            self.results.skip("print", venv.name, "jtbot_sim", f"{SIM_LAUNCH} does not exist yet")
        for what, path in cases:
            for flag in ("--show-args", "--print"):
                argv = [str(venv.mlaunch), str(path), flag]
                try:
                    samples = [self.wall(argv) for _ in self.runs()][1:]
                except BenchError as e:
                    self.results.skip("print", venv.name, f"{flag} {what}", str(e))
                    continue
                target = Target(0.05) if (flag, path) == ("--show-args", one) else None
                self.results.rows.append(
                    Row(
                        "print",
                        f"{flag} {what}",
                        venv.name,
                        "s",
                        samples,
                        "python -c pass",
                        floor,
                        target,
                        {"file": str(path.name), "flag": flag},
                    )
                )

    # --- output throughput --------------------------------------------------------------------

    def output(self, venv: Venv, floors: dict[str, list[dict[str, float]]]) -> None:
        n, m = self.config.output_procs, self.config.output_lines
        m_ref = self.config.reference_output_lines
        emitter = [str(self.scripts.emit), str(m)]
        for mode in ("screen", "log"):
            stem = f"emit_{mode}"
            path = gen.write(
                [gen.many_children(stem, n, emitter, output=mode)], "py", self.launches / stem
            )
            ref_path = gen.write(
                [gen.many_children(stem, n, [str(self.scripts.emit), str(m_ref)], output=mode)],
                "py",
                self.launches / f"{stem}_ref",
            )
            measure = functools.partial(self._reference_output, ref_path, mode, n * m_ref)
            samples: list[dict[str, float]] = []
            try:
                for i in self.runs():
                    if len(floors.setdefault(mode, [])) < i:
                        floors[mode].append(self.output_floor(mode, n, m))
                    one = self.output_run([str(venv.mlaunch), str(path)], mode, n * m)
                    if i:
                        samples.append(one)
                    self.reference_turn("output", f"output={mode}", i, measure)
            except BenchError as e:
                self.results.skip("output", venv.name, f"{n} x {m} lines, output={mode}", str(e))
                continue
            refs = self.reference_samples(f"output={mode}")
            self._output_rows(venv, mode, n, m, samples, floors[mode], refs)

    def _reference_output(
        self, path: Path, mode: str, expected: int, ref: Reference
    ) -> dict[str, float]:
        return self.output_run(ref.argv(path), mode, expected, ref.env)

    def _output_rows(
        self,
        venv: Venv,
        mode: str,
        n: int,
        m: int,
        samples: list[dict[str, float]],
        floors: list[dict[str, float]],
        refs: list[dict[str, float]],
    ) -> None:
        where = "its stdout (a pipe)" if mode == "screen" else "the log files"
        params = {"processes": n, "lines_each": m, "output": mode}
        if refs:
            params["reference_lines_each"] = self.config.reference_output_lines
        floor_name = "cat" if mode == "screen" else "cat > file"
        self.results.rows.append(
            Row(
                "output",
                f"{n} x {m:,} lines to {where}",
                venv.name,
                "lines/s",
                [s["rate"] for s in samples],
                floor_name,
                [f["rate"] for f in floors],
                Target(200_000, higher_is_better=True) if mode == "screen" else None,
                params,
                reference_samples=[r["rate"] for r in refs],
            )
        )
        self.results.rows.append(
            Row(
                "output",
                f"CPU while passing them (output={mode})",
                venv.name,
                "cores",
                [s["cpu_share"] for s in samples],
                floor_name,
                [f["cpu_share"] for f in floors],
                Target(1.0) if mode == "screen" else None,
                {**params, "cpu_seconds": [s["cpu"] for s in samples]},
                reference_samples=[r["cpu_share"] for r in refs],
            )
        )
        if mode == "screen":
            self.results.rows.append(
                Row(
                    "output",
                    "lines dropped from stdout (reader behind)",
                    venv.name,
                    "lines",
                    [s["dropped"] for s in samples],
                    floor_name,
                    [0.0 for _ in floors],
                    None,
                    params,
                )
            )

    def output_run(
        self,
        argv: Sequence[str],
        mode: str,
        expected: int,
        reference_env: dict[str, str] | None = None,
    ) -> dict[str, float]:
        """mlaunch passing N children's lines: rate to its stdout pipe or to the log files.

        With ``reference_env``, ros2 launch: its output=screen lines go to stdout only, its
        output=log lines into launch.log (mlaunch: each process's own log file, always).
        """
        log_dir = self.logs / f"out-{time.monotonic_ns()}"
        base = self.env if reference_env is None else reference_env
        env = {**base, "ROS_LOG_DIR": str(log_dir)}
        started = time.perf_counter()
        popen = subprocess.Popen(
            list(argv),
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        proc = pr.Launched(popen, os.pidfd_open(popen.pid), started)
        counter = LineCounter(gen.EMIT_TOKEN, proc.pid)
        try:
            assert popen.stdout is not None
            deadline = time.perf_counter() + 120
            pr.read_pipe_until_exit(popen.stdout.fileno(), proc, deadline, counter.feed)
            proc.wait_exit_keep_zombie(deadline)
            cpu_exit = pr.fine_cpu_seconds(proc.pid)
            code = proc.reap(deadline)
            if code != 0:
                raise BenchError(f"mlaunch exited {code}: {one_line(counter.text())}")
            reference = reference_env is not None
            logged = count_token_in_logs(log_dir, gen.EMIT_TOKEN, with_launch_log=reference)
            if logged != (0 if reference and mode == "screen" else expected):
                raise BenchError(f"{logged} of {expected} lines in the log files")
            if mode == "screen":
                # By design mlaunch drops screen lines a reader cannot take (never the log
                # files); its notices say how many, and every line must be accounted for.
                if counter.count + counter.dropped != expected:
                    raise BenchError(
                        f"{counter.count} of {expected} lines reached stdout,"
                        f" {counter.dropped} reported dropped"
                    )
                return counter.window()
            # Log files are only seen complete at exit: the window is from the first
            # "process started" message to mlaunch's exit (its own exit work included).
            start, end = counter.started_msg, proc.exited_at
            if start is None or end is None or end <= start:
                raise BenchError(f"no output window: {one_line(counter.text())}")
            cpu = cpu_exit - counter.cpu_start
            return {"rate": expected / (end - start), "cpu": cpu, "cpu_share": cpu / (end - start)}
        finally:
            proc.kill()
            pr.kill_descendants()
            shutil.rmtree(log_dir, ignore_errors=True)

    def output_floor(self, mode: str, n: int, m: int) -> dict[str, float]:
        """The same N emitters writing into one pipe that ``cat`` copies to us or to a file."""
        read_end, write_end = os.pipe()
        sink_path = self.tmp / "cat-sink.txt"
        sink = open(sink_path, "wb") if mode == "log" else None  # noqa: SIM115
        started = time.perf_counter()
        popen = subprocess.Popen(
            ["cat"],
            env=self.env,
            stdin=read_end,
            stdout=sink if sink is not None else subprocess.PIPE,
            start_new_session=True,
        )
        os.close(read_end)
        cat = pr.Launched(popen, os.pidfd_open(popen.pid), started)
        emitters: list[subprocess.Popen[bytes]] = []
        # N writers share cat's input pipe: their writes above PIPE_BUF interleave mid-line, so
        # newlines are counted (bytes are never lost, only mixed), not tokens.
        counter = LineCounter(None, cat.pid)
        try:
            for _ in range(n):
                emitters.append(
                    subprocess.Popen(
                        [str(self.scripts.emit), str(m)],
                        env=self.env,
                        stdin=subprocess.DEVNULL,
                        stdout=write_end,
                        start_new_session=True,
                    )
                )
            os.close(write_end)
            write_end = -1
            deadline = time.perf_counter() + 120
            if popen.stdout is not None:
                pr.read_pipe_until_exit(popen.stdout.fileno(), cat, deadline, counter.feed)
            cat.wait_exit_keep_zombie(deadline)
            cpu = pr.fine_cpu_seconds(cat.pid)
            cat.reap(deadline)
            for e in emitters:
                e.wait(timeout=10)
            if mode == "screen":
                if counter.count != n * m:
                    raise BenchError(f"floor cat passed {counter.count} of {n * m} lines")
                return counter.window()
            assert sink is not None and cat.exited_at is not None
            sink.close()
            lines = count_token_in_file(sink_path, b"\n")
            if lines != n * m:
                raise BenchError(f"floor cat wrote {lines} of {n * m} lines")
            span = cat.exited_at - started
            return {"rate": lines / span, "cpu": cpu, "cpu_share": cpu / span}
        finally:
            if write_end >= 0:
                os.close(write_end)
            if sink is not None:
                sink.close()
            cat.kill()
            pr.kill_descendants()
            sink_path.unlink(missing_ok=True)

    # --- simulation ---------------------------------------------------------------------------

    def fleet(self, venv: Venv, domain: int) -> None:
        """``mlaunch export --to ansible`` of a launch split by machine (two machines and a node
        given none), deployed by ansible-playbook to three hosts on two private sshd daemons
        and torn down again, each run; the floor is a one-task play (ping) on the same hosts:
        Ansible's own cost of reaching them. Wall time: the load of the machine is in it."""
        import fleet as fl
        import sshd

        why = fl.missing()
        if why is None and Path(sys.executable).parent != venv.python.parent:
            why = f"runs with the ros venv's interpreter ({venv.python})"
        if why is not None:
            self.results.skip("fleet", venv.name, "ansible deploy", why)
            return
        env = {
            **self.env,
            "ROS_DOMAIN_ID": str(domain),
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        }
        work = self.tmp / "fleet"
        work.mkdir()
        servers: list[sshd.Server] = []
        deploys: list[float] = []
        teardowns: list[float] = []
        pings: list[float] = []
        try:
            for name in ("r1", "r2"):
                (work / f"sshd-{name}").mkdir()
                servers.append(sshd.start(work / f"sshd-{name}", alias=name))
            out = fl.export(work, "split", fl.SPLIT, env)
            inv, _hosts = fl.split_inventory(out, servers, env, work / "robots")
            (out / "ping.yml").write_text(
                "- hosts: all\n  gather_facts: false\n  tasks:\n    - ansible.builtin.ping:\n"
            )
            for _ in range(self.config.runs):
                pings.append(self._play(fl, out, inv, "ping.yml", env))
                deploys.append(self._play(fl, out, inv, "deploy.yml", env))
                teardowns.append(self._play(fl, out, inv, "teardown.yml", env))
        except BenchError as e:
            self.results.skip("fleet", venv.name, "ansible deploy", str(e))
            return
        finally:
            for server in servers:
                sshd.stop(server)
        params = {"hosts": 3, "shares": ["r1", "r2", "local"], "load": list(os.getloadavg())}
        floor = "ansible ping play, same hosts"
        self.results.rows.append(
            Row(
                "fleet",
                "ansible deploy, launch split over 3 hosts, until all ready",
                venv.name,
                "s",
                deploys,
                floor,
                pings,
                params=params,
            )
        )
        self.results.rows.append(
            Row(
                "fleet",
                "ansible teardown, 3 hosts",
                venv.name,
                "s",
                teardowns,
                floor,
                pings,
                params=params,
            )
        )

    @staticmethod
    def _play(fl: Any, out: Path, inv: Path, book: str, env: dict[str, str]) -> float:
        started = time.perf_counter()
        done = fl.play(out, inv, book, env=env)
        took = time.perf_counter() - started
        if done.returncode != 0:
            raise BenchError(f"{book} failed: {one_line(done.stdout[-600:] + done.stderr)}")
        return took

    def sim(self, venv: Venv, domain: int) -> None:
        probe_ok = subprocess.run(
            [str(venv.python), "-c", "import rclpy, rosgraph_msgs.msg"],
            env=self.env,
            capture_output=True,
        )
        if probe_ok.returncode != 0:
            self.results.skip("sim", venv.name, "simulation", "rclpy is not importable here")
            return
        if not (REPO / "mlaunch" / "standins" / "sim.py").exists():
            self.results.skip("sim", venv.name, "simulation", "mlaunch/standins/sim.py missing")
            return
        env = {
            **self.env,
            "ROS_DOMAIN_ID": str(domain),
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
            "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
        }
        env.pop("ROS_LOCALHOST_ONLY", None)
        how, start = self._sim_starter(venv, env)
        samples: list[dict[str, float]] = []
        robot = True
        try:
            for _ in range(self.config.sim_runs):
                one = self.sim_run(venv, env, start)
                robot = robot and bool(one.pop("robot"))
                samples.append(one)
        except BenchError as e:
            self.results.skip("sim", venv.name, f"simulation ({how})", str(e))
            return
        note = how + ("" if robot else "; no robot appeared (no /scan publisher): world only")
        params = {"how": how, "window_s": self.config.sim_seconds, "robot": robot}
        rows: list[tuple[str, str, str, Target | None]] = [
            ("simulator real-time factor", "x", "rtf", Target(0.97, higher_is_better=True)),
            ("simulator CPU", "cores", "sim_cpu", Target(1 / 3)),
        ]
        if "mlaunch_cpu" in samples[0]:
            rows.append(("mlaunch CPU while supervising it", "cores", "mlaunch_cpu", None))
        for name, unit, key, target in rows:
            values = [s[key] for s in samples]
            self.results.rows.append(
                Row("sim", name, venv.name, unit, values, target=target, params=params, note=note)
            )

    def _sim_starter(
        self, venv: Venv, env: dict[str, str]
    ) -> tuple[str, Callable[[], list[pr.Launched]]]:
        """How to start the simulation: the jtbot launch file if mlaunch runs it, else directly."""
        if SIM_LAUNCH.exists():
            check = subprocess.run(
                [str(venv.mlaunch), str(SIM_LAUNCH), "--print"],
                env=env,
                capture_output=True,
                text=True,
            )
            if check.returncode == 0:
                out = self.tmp / "sim-out.txt"

                def via_launch() -> list[pr.Launched]:
                    with open(out, "wb") as f:
                        return [
                            pr.launch(
                                [str(venv.mlaunch), str(SIM_LAUNCH)],
                                env,
                                stdout=f.fileno(),
                                stderr=subprocess.STDOUT,
                            )
                        ]

                return "mlaunch launches/jtbot_sim.launch.py", via_launch
            self.results.skip(
                "sim",
                venv.name,
                "via launches/jtbot_sim.launch.py",
                f"mlaunch cannot run it yet ({one_line(check.stderr)}); sim + spawn started directly",
            )
        urdf = self.tmp / "jtbot.urdf"
        xacro = subprocess.run(
            [str(venv.python), "-m", "xacro", str(SIM_XACRO), "-o", str(urdf)],
            env=env,
            capture_output=True,
            text=True,
        )
        spawn = xacro.returncode == 0 and (REPO / "mlaunch" / "standins" / "spawn.py").exists()
        how = "python -m mlaunch.standins.sim jt.world" + (" + spawn" if spawn else "")

        def direct() -> list[pr.Launched]:
            py = str(venv.python)
            out = open(self.tmp / "sim-out.txt", "wb")  # noqa: SIM115
            started = [
                pr.launch(
                    [py, "-m", "mlaunch.standins.sim", str(SIM_WORLD)],
                    env,
                    stdout=out.fileno(),
                    stderr=subprocess.STDOUT,
                )
            ]
            if spawn:
                spawn_argv = [
                    py,
                    "-m",
                    "mlaunch.standins.spawn",
                    "spawn_entity.py",
                    "-entity",
                    "jtbot",
                    "-file",
                    str(urdf),
                ]
                started.append(
                    pr.launch(spawn_argv, env, stdout=out.fileno(), stderr=subprocess.STDOUT)
                )
            out.close()
            return started

        if not spawn:
            self.results.skip("sim", venv.name, "spawn", f"xacro failed: {one_line(xacro.stderr)}")
        return how, direct

    def sim_run(
        self, venv: Venv, env: dict[str, str], start: Callable[[], list[pr.Launched]]
    ) -> dict[str, float]:
        procs = start()
        probe: pr.Launched | None = None
        try:
            probe_argv = [
                str(venv.python),
                str(HERE / "clock_probe.py"),
                str(self.config.sim_seconds),
                "--wait-topic",
                "/scan",
            ]
            probe = pr.launch(probe_argv, env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            assert probe.popen.stdout is not None
            stream = probe.popen.stdout
            line = stream.readline().decode()
            if not line.startswith("window"):
                err = probe.popen.stderr.read().decode() if probe.popen.stderr else ""
                raise BenchError(f"clock probe: {one_line(err) or 'no output'}")
            root = procs[0].pid
            sim_pid = root
            if not self._is_sim(root):  # started by mlaunch: find it below
                found = pr.find_descendant(root, lambda argv: "mlaunch.standins.sim" in argv)
                if found is None:
                    raise BenchError("no simulator process found below mlaunch")
                sim_pid = found
            robot = line.strip().endswith("robot=1")
            c0, m0, t0 = pr.cpu_seconds(sim_pid), pr.fine_cpu_seconds(root), time.perf_counter()
            k0 = pr.cpu_seconds(root)
            result_line = stream.readline().decode()
            c1, m1, t1 = pr.cpu_seconds(sim_pid), pr.fine_cpu_seconds(root), time.perf_counter()
            k1 = pr.cpu_seconds(root)
            if m1 < m0:  # a thread of mlaunch ended in the window: its share left the live sum
                m0, m1 = k0, k1  # the whole process's ticks count the ended threads too
            data = json.loads(result_line) if result_line.startswith("{") else None
            if data is None:
                err = probe.popen.stderr.read().decode() if probe.popen.stderr else ""
                raise BenchError(f"clock probe: {one_line(err) or 'no result'}")
            result = {
                "rtf": (data["sim1"] - data["sim0"]) / (data["wall1"] - data["wall0"]),
                "sim_cpu": (c1 - c0) / (t1 - t0),
                "robot": float(robot),
            }
            if root != sim_pid:
                result["mlaunch_cpu"] = (m1 - m0) / (t1 - t0)
            return result
        finally:
            if probe is not None:
                probe.kill()
            for proc in procs:
                if proc.returncode is None:
                    try:
                        os.kill(proc.pid, signal.SIGINT)
                        proc.reap(time.perf_counter() + 15)
                    except (BenchError, ProcessLookupError):
                        pass
                proc.kill()
            pr.kill_descendants()

    @staticmethod
    def _is_sim(pid: int) -> bool:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                return b"mlaunch.standins.sim" in f.read()
        except OSError:
            return False

    # --- where the CPU goes until the first child ---------------------------------------------

    def profile(self, venv: Venv) -> None:
        """mlaunch's CPU until its first child, bucket by bucket (benchmarks/startup_profile.py),
        for a one-process and a one-Node launch whose child is ``true``, and until the 100th of a
        100-process launch; then the launcher's CPU to start one child (``spawn_cost``)."""
        true = shutil.which("true") or "/bin/true"
        one = gen.write([gen.many_children("true1", 1, [true])], "py", self.launches / "true1")
        node, prefix = gen.write_node_launch(self.launches / "node_true", Path(true), self.fifo)
        many = gen.write([gen.many_children("true100", 100, [true])], "py", self.launches / "t100")
        cases = (
            ("one-process launch", one, self.env, 1),
            ("one-Node launch", node, {**self.env, "AMENT_PREFIX_PATH": str(prefix)}, 1),
            # Until the 100th start: resolving 100 processes, then starting them.
            ("100-process launch", many, self.env, 100),
        )
        for what, path, env, children in cases:
            try:
                found = startup_profile.profile(
                    [str(venv.mlaunch), str(path)], env, self.config.runs, children=children
                )
            except (RuntimeError, subprocess.TimeoutExpired) as e:
                self.results.skip("profile", venv.name, what, str(e))
                continue
            for bucket, samples in found.items():
                self.results.rows.append(
                    Row("profile", f"{what}: {bucket}", venv.name, "s", samples, note="CPU")
                )
        self.spawn_cost(venv)

    def spawn_cost(self, venv: Venv) -> None:
        """The launcher's CPU to start one child (benchmarks/spawn_cost.py): engine.spawning,
        and os.posix_spawn for reference, beside Popen (the floor's way), with 0 and 300 other
        fds open."""
        argv = [str(venv.python), str(HERE / "spawn_cost.py"), "--json"]
        argv += ["--rounds", str(self.config.runs)]
        done = subprocess.run(
            argv, env=self.floor_env(venv), capture_output=True, text=True, timeout=300
        )
        if done.returncode != 0:
            self.results.skip("profile", venv.name, "a child's start", one_line(done.stderr))
            return
        found = json.loads(done.stdout)
        popen = found.pop("popen")
        for way, by_fds in found.items():
            for fds, samples in by_fds.items():
                name = f"a child's start, {way}, {fds} other fds open"
                note = "CPU" if way == "spawning" else "CPU; closes no inheritable fd (< 3.13)"
                self.results.rows.append(
                    Row(
                        "profile",
                        name,
                        venv.name,
                        "s",
                        samples,
                        "Popen(close_fds=True)",
                        popen[fds],
                        None,
                        {"fds": int(fds)},
                        note=note,
                    )
                )

    # --- import time ---------------------------------------------------------------------------

    def importtime(self, venv: Venv) -> None:
        path = gen.write([gen.many_children("true1", 1, ["true"])], "py", self.launches / "true1")
        # As a user starts it (the mlaunch command scripts/setup writes is a shell script), with
        # every interpreter reporting its imports (the last one's are parsed).
        env = {**self.env, "PYTHONPROFILEIMPORTTIME": "1"}
        argv = [str(venv.mlaunch), str(path)]
        done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=60)
        if done.returncode != 0:
            self.results.skip("importtime", venv.name, "one-process launch", done.stderr)
            return
        self.results.importtime[venv.name] = parse_importtime(done.stderr)

    # --- the plan cache: cold and warm resolves ------------------------------------------------

    def plan_cache(self, venv: Venv) -> None:
        """benchmarks/plan_cache_bench.py: big trees resolved cold and from the cache."""
        import plan_cache_bench

        cases = []
        for fmt in self.formats if self.config.mode == "full" else ["py"]:
            top = gen.write(gen.big_system(), fmt, self.launches / f"cache_big_{fmt}")
            cases.append(plan_cache_bench.Case(f"big synthetic {fmt}", [str(top)], self.env))
        tree = self._autoware_tree() if self.config.mode == "full" else "not in --quick runs"
        if isinstance(tree, str):
            self.results.skip("plancache", venv.name, "Autoware tree", tree)
        else:
            argv = [str(tree.launch_file), *tree.arguments]
            cases.append(
                plan_cache_bench.Case("Autoware planning_simulator", argv, tree.environ(self.env))
            )
        say = lambda line: print(line, file=sys.stderr, flush=True)  # noqa: E731
        try:
            figures = plan_cache_bench.measure(self.config.runs, venv.mlaunch, cases, self.tmp, say)
        except BenchError as e:
            self.results.skip("plancache", venv.name, "plan cache", str(e))
            return
        for f in figures:
            target = None if f.target is None else Target(f.target)
            self.results.rows.append(
                Row("plancache", f.name, venv.name, f.unit, f.samples, f.floor_name,
                    f.floor_samples, target, {"runs": self.config.runs}, f.note)
            )  # fmt: skip

    def _autoware_tree(self) -> Any:
        """The Autoware fixture (built once from its fetched sources), or why not."""
        import autoware_tree as fixture

        sources = fixture.CACHE / "sources"
        if not fixture.have_sources(sources):
            return f"no Autoware sources in {sources}: run 'benchmarks/autoware_tree.py' once"
        try:
            return fixture.build(sources)
        except fixture.FixtureError as e:
            return f"the fixture cannot be built: {e}"

    # --- Autoware's planning_simulator, beside ros2 launch -------------------------------------

    def autoware(self, venv: Venv, domain: int) -> None:
        """benchmarks/autoware_bench.py: the real tree, mlaunch and ros2 launch alternating."""
        import autoware_bench

        if self.reference is None:  # not built, or --no-reference: the figures are ratios to it
            reason = "needs the reference ros2 launch (not found, or --no-reference)"
            self.results.skip("autoware", venv.name, "Autoware tree", reason)
            return
        env = {
            **self.env,
            "ROS_DOMAIN_ID": str(domain),
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        }
        runs = self.config.runs  # each ros2 launch start takes 15 s (quiet) to 100 s (loaded)
        say = lambda line: print(line, file=sys.stderr, flush=True)  # noqa: E731
        try:
            figures = autoware_bench.measure(runs, venv.mlaunch, venv.python, env, self.tmp, say)
        except BenchError as e:
            self.results.skip("autoware", venv.name, "Autoware tree", str(e))
            return
        if isinstance(figures, str):
            self.results.skip("autoware", venv.name, "Autoware tree", figures)
            return
        for f in figures:
            target = None if f.target is None else Target(f.target)
            self.results.rows.append(
                Row("autoware", f.name, venv.name, f.unit, f.samples, f.floor_name,
                    f.floor_samples, target, {"runs": runs}, f.note, f.reference_samples)
            )  # fmt: skip


class LineCounter:
    """Counts the benchmark lines in a stream as it arrives and notes when they came.

    The writer's CPU time is read from /proc with the line count at most every SAMPLE_EVERY
    seconds (the reader must stay fast: mlaunch drops screen output a slow reader cannot
    take), so the rate and the CPU share cover the same window: from the first sample to the
    last, both taken as chunks of lines arrive, without the writer's start-up or exit.
    """

    SAMPLE_EVERY = 0.005

    def __init__(self, token: bytes | None, pid: int) -> None:
        self.token = token  # None: every line counts (the stream is nothing but benchmark lines)
        self.pid = pid
        self.count = 0
        self.started_msg: float | None = None
        self.cpu_start = 0.0
        self.samples: list[tuple[float, float, int]] = []  # (time, cpu, lines so far)
        self.dropped = 0
        self._carry = b""
        self._head = b""

    def feed(self, data: bytes, now: float) -> None:
        if len(self._head) < 4096:
            self._head += data[: 4096 - len(self._head)]
        if self.started_msg is None and b"process started" in data:
            self.started_msg = now
            self.cpu_start = self._cpu()
        data = self._carry + data
        cut = data.rfind(b"\n") + 1
        self._carry = data[cut:]
        found = data.count(self.token if self.token is not None else b"\n", 0, cut)
        if self.token is not None and b"fell behind" in data:
            self.dropped += sum(int(n) for n in DROP_NOTICE.findall(data))
        if found:
            self.count += found
            if not self.samples or now - self.samples[-1][0] >= self.SAMPLE_EVERY:
                self.samples.append((now, self._cpu(), self.count))

    def _cpu(self) -> float:
        try:
            return pr.fine_cpu_seconds(self.pid)
        except OSError:
            return 0.0

    def window(self) -> dict[str, float]:
        """Lines per second and the writer's CPU share between the first and last sample."""
        if len(self.samples) < 2:
            raise BenchError(f"too short an output window: {one_line(self.text())}")
        (t0, c0, n0), (t1, c1, n1) = self.samples[0], self.samples[-1]
        return {
            "rate": (n1 - n0) / (t1 - t0),
            "cpu": c1 - c0,
            "cpu_share": (c1 - c0) / (t1 - t0),
            "dropped": float(self.dropped),
        }

    def text(self) -> str:
        return self._head.decode(errors="replace")


DROP_NOTICE = re.compile(rb"fell behind: (\d+) lines")


def count_token_in_file(path: Path, token: bytes) -> int:
    count, carry = 0, b""
    with open(path, "rb") as f:
        while chunk := f.read(1 << 20):
            data = carry + chunk
            cut = data.rfind(b"\n") + 1
            count += data.count(token, 0, cut)
            carry = data[cut:]
    return count + carry.count(token)


def count_token_in_logs(log_base: Path, token: bytes, with_launch_log: bool = False) -> int:
    """Benchmark lines in every process's own log file of the one run below ``log_base``
    (and in launch.log, where ros2 launch writes output=log lines)."""
    total = 0
    for path in log_base.rglob("*.log"):
        if with_launch_log or path.name != "launch.log":
            total += count_token_in_file(path, token)
    return total


IMPORT_LINE = re.compile(r"^import time:\s+(\d+)\s+\|\s+(\d+)\s+\|(\s+)(\S+)\s*$")


def parse_importtime(stderr: str) -> dict[str, Any]:
    """Top 10 cumulative imports of the last interpreter (the ROS hook re-execs once)."""
    segments = stderr.split("import time: self [us] | cumulative | imported package")
    entries = []
    for line in segments[-1].splitlines():
        match = IMPORT_LINE.match(line)
        if match:
            own, cumulative, indent, name = match.groups()
            entries.append((name, int(own), int(cumulative), (len(indent) - 1) // 2))
    top = sorted(entries, key=lambda e: e[2], reverse=True)[:10]
    return {
        "total_ms": sum(e[1] for e in entries) / 1000,
        "modules": len(entries),
        "rclpy_imported": any(e[0] == "rclpy" or e[0].startswith("rclpy.") for e in entries),
        "top": [
            {"module": name, "cumulative_ms": cum / 1000, "self_ms": own / 1000, "depth": depth}
            for name, own, cum, depth in top
        ],
    }


# --- the table ------------------------------------------------------------------------------


def fmt_value(value: float | None, unit: str) -> str:
    if value is None:
        return "-"
    if unit == "s":
        return f"{value * 1000:.1f} ms" if value < 10 else f"{value:.1f} s"
    if unit == "lines/s":
        return f"{value / 1000:,.0f}k/s"
    if unit == "MB":
        return f"{value:.1f} MB"
    if unit == "cores":
        return f"{value:.3f} cores"
    if unit == "lines":
        return f"{value:,.0f}"
    if unit == "x":
        return f"{value:.3f}x"
    return f"{value:g} {unit}"


def format_table(results: Results) -> str:
    """The rows as a fixed-width table, grouped, then the skips and the import-time tops."""
    head: tuple[str, ...] = (
        "what",
        "venv",
        "mlaunch best",
        "median",
        "floor",
        "floor med",
        "ratio",
        "ros2 launch",
        "vs ros2",
        "target",
        "",
    )
    lines_out: list[tuple[str, ...]] = []
    for group in SECTIONS:
        rows = [r for r in results.rows if r.group == group]
        if not rows:
            continue
        lines_out.append((f"[{group}]",))
        for r in rows:
            ratio = "-" if r.ratio is None else f"{r.ratio:.2f}"
            target = r.target.text(r.unit) if r.target else ""
            status = r.target.status(r.median) if r.target else ""
            floor_best = best_of(r.floor_samples, r.unit) if r.floor_samples else None
            floor = f"{r.floor_name}: {fmt_value(floor_best, r.unit)}" if r.floor_samples else "-"
            cells: tuple[str, ...] = (
                r.name,
                r.venv,
                fmt_value(r.best, r.unit),
                fmt_value(r.median, r.unit),
                floor,
                fmt_value(r.floor_median, r.unit),
                ratio,
                fmt_value(r.reference_median, r.unit),
                "-" if r.reference_ratio is None else f"{r.reference_ratio:.2f}",
                target,
                status,
            )
            lines_out.append(cells)
    widths = [len(h) for h in head]
    for cells in lines_out:
        if len(cells) == len(head):
            widths = [max(w, len(c)) for w, c in zip(widths, cells, strict=True)]
    rule = "  ".join("-" * w for w in widths)
    meta = results.meta
    text = [
        f"mlaunch benchmarks, {meta.get('mode')} mode, {meta.get('config', {}).get('runs')} runs"
        f" after a warm-up, {meta.get('cpus')} CPUs, load average before/after:"
        f" {_load(meta.get('loadavg_before'))} / {_load(meta.get('loadavg_after'))}",
        "best = min (max for rates); ratio = median / floor median; ros2 launch = its median in"
        " the same run, vs ros2 = median / that; PASS/MISS on the median",
        "",
        "  ".join(h.ljust(w) for h, w in zip(head, widths, strict=True)).rstrip(),
        rule,
    ]
    for cells in lines_out:
        if len(cells) == 1:
            text.append(cells[0])
        else:
            text.append("  ".join(c.ljust(w) for c, w in zip(cells, widths, strict=True)).rstrip())
    notes = sorted({f"[{r.group}] {r.venv}: {r.note}" for r in results.rows if r.note})
    notes += [
        f"[{t['group']}] ros2 launch failed a run of {t['figure']} (tried again): {t['reason']}"
        for t in meta.get("reference_retries", [])
    ]
    if notes:
        text += ["", "notes:"] + [f"  {n}" for n in notes]
    if results.skips:
        text += ["", "skipped:"]
        text += [f"  [{s.group}] {s.venv}: {s.what}: {s.reason}" for s in results.skips]
    for venv, info in results.importtime.items():
        rclpy = "YES (regression)" if info["rclpy_imported"] else "no"
        text += [
            "",
            f"-X importtime, one-process launch, {venv} venv: {info['total_ms']:.1f} ms in"
            f" {info['modules']} modules; rclpy imported: {rclpy}; top 10 cumulative:",
        ]
        text += [
            f"  {t['cumulative_ms']:7.1f} ms  {'  ' * t['depth']}{t['module']}" for t in info["top"]
        ]
    return "\n".join(text) + "\n"


# --- the README's figures -----------------------------------------------------------------

README = REPO / "README.md"
README_BEGIN = "<!-- benchmarks/run.py --readme: begin -->"
README_END = "<!-- benchmarks/run.py --readme: end -->"
# (what the README calls it, the row's group and name in the results); ros venv first.
README_ROWS = (
    (
        "first child running, one-process launch, resolved",
        "startup",
        "first child running, py, N=1",
    ),
    ("its CPU until then (from exec)", "startup", "CPU until the first child runs, py, N=1"),
    (
        "the same, a repeated start (quick start)",
        "startup",
        "first child running, py, repeated start (quick start)",
    ),
    ("its CPU until then", "startup", "CPU until the first child runs, py, repeated start"),
    (
        "first child running, one-Node launch, resolved",
        "startup",
        "first child running, py, one Node",
    ),
    (
        "the same, a repeated start (quick start)",
        "startup",
        "first child running, py, one Node, repeated start (quick start)",
    ),
    ("all 100 children running, resolved", "startup", "all 100 children running, py"),
    (
        "the same, a repeated start (quick start)",
        "startup",
        "all 100 children running, py, repeated start (quick start)",
    ),
    ("100 children gone after Ctrl-C", "shutdown", "SIGINT until all gone, N=100"),
    ("peak memory with 100 children", "memory", "peak RSS (VmHWM), 100 children"),
    ("lines/s from 4 children to a pipe", "output", "lines to its stdout (a pipe)"),
)


# Rows of the opt-in groups, shown when the results hold them (--only autoware,plancache).
README_OPTIONAL_ROWS = (
    (
        "Autoware planning_simulator: launcher CPU until all up",
        "autoware",
        "launcher CPU until all up",
    ),
    (
        "its ratio to ros2 launch",
        "autoware",
        "launcher CPU until all up, mlaunch / ros2 launch",
    ),
    (
        "Autoware: peak RSS, launcher and helpers",
        "autoware",
        "peak RSS, launcher and its helpers",
    ),
    ("its ratio to ros2 launch", "autoware", "peak RSS, mlaunch / ros2 launch"),
    ("Autoware: `--print` of the tree", "autoware", "--print of the tree"),
    (
        "Autoware: resolve from the plan cache, CPU",
        "plancache",
        "plan cache, Autoware planning_simulator: resolve CPU, warm",
    ),
)


def readme_table(data: dict[str, Any]) -> str:
    """The README's short figures table, from a results JSON (medians; ros venv preferred)."""
    rows = data.get("rows", [])
    venvs = [v for v in ("ros", "plain") if any(r["venv"] == v for r in rows)]
    if not venvs:
        raise BenchError("the results hold no rows of the ros or plain venv")
    venv = venvs[0]
    meta = data.get("meta", {})
    out = [
        "| figure | mlaunch | floor | ros2 launch | ratio to floor / to ros2 launch | target |",
        "|---|---|---|---|---|---|",
    ]
    missing = []
    optional = {label for label, _, _ in README_OPTIONAL_ROWS}
    for label, group, name in (*README_ROWS, *README_OPTIONAL_ROWS):
        row = next(
            (r for r in rows if r["venv"] == venv and r["group"] == group and r["name"] == name),
            None,
        ) or next(
            (
                r
                for r in rows
                if r["venv"] == venv and r["group"] == group and r["name"].endswith(name)
            ),
            None,
        )
        if row is None:
            if label not in optional:
                missing.append(label)
            continue
        unit = row["unit"]
        floor, ref = row.get("floor"), row.get("reference")
        cells = [
            label,
            fmt_value(row["mlaunch"]["median"], unit),
            f"{fmt_value(floor['median'], unit)} ({floor['name']})" if floor else "-",
            fmt_value(ref["median"], unit) if ref else "-",
            " / ".join(_ratio_text(x) for x in (row["ratio"], row.get("reference_ratio"))),
            ""
            if row["target"] is None
            else f"{'≥' if row['target']['op'] == '>=' else '≤'} "
            f"{fmt_value(row['target']['limit'], unit)}",
        ]
        out.append("| " + " | ".join(cells) + " |")
    if missing:
        raise BenchError(f"the results lack the rows of: {', '.join(missing)}")
    load = meta.get("loadavg_before"), meta.get("loadavg_after")
    out += [
        "",
        f"Medians of {meta.get('config', {}).get('runs')} runs each, {meta.get('mode')} mode,"
        f" {venv} venv, commit {meta.get('git') or '?'}, {str(meta.get('when', '?'))[:10]},"
        f" {meta.get('cpus')} CPUs, load average {_load(load[0])} before, {_load(load[1])}"
        " after; floor and ros2 launch measured in the same run, alternating with mlaunch."
        " Regenerate: `benchmarks/run.py --json FILE`, then `benchmarks/run.py --readme FILE`.",
    ]
    return "\n".join(out) + "\n"


def _ratio_text(ratio: float | None) -> str:
    if ratio is None:
        return "-"
    return f"{ratio:.3f}x" if ratio < 0.1 else f"{ratio:.2f}x"


def render_readme(results_json: Path, readme: Path = README) -> None:
    """Replace the text between the README's markers with the table of ``results_json``."""
    table = readme_table(json.loads(results_json.read_text()))
    text = readme.read_text()
    begin, end = text.find(README_BEGIN), text.find(README_END)
    if begin < 0 or end < begin:
        raise BenchError(f"{readme}: no {README_BEGIN!r} ... {README_END!r} markers, in that order")
    head = text[: begin + len(README_BEGIN)]
    readme.write_text(head + "\n" + table + text[end:])


# --- main -----------------------------------------------------------------------------------


def _load(values: Any) -> str:
    return "?" if not values else f"{values[0]:.2f}"


def parse_args(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="benchmarks/run.py", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="few runs, small N (~1 min)")
    parser.add_argument("--json", metavar="FILE", help="write the JSON here ('-' for stdout)")
    parser.add_argument("--venv", choices=("ros", "plain", "both"), default="both")
    parser.add_argument(
        "--only",
        metavar="GROUPS",
        help=f"comma list of {', '.join(GROUPS)} (default: all but"
        f" {', '.join(OPT_IN_GROUPS)}, measured only when named)",
    )
    parser.add_argument("--runs", type=int, help="measured runs per figure (after a warm-up)")
    parser.add_argument("--ros-domain", type=int, help="ROS_DOMAIN_ID for the simulation")
    parser.add_argument("--keep-temp", action="store_true", help="keep the generated files")
    parser.add_argument(
        "--readme",
        metavar="RESULTS_JSON",
        help="measure nothing: write the README's figures table from this results JSON",
    )
    parser.add_argument(
        "--no-reference",
        action="store_true",
        help="leave out the ros2 launch column (measured where tests/reference.py finds it)",
    )
    args = parser.parse_args(list(argv))
    if args.only:
        unknown = set(args.only.split(",")) - set(GROUPS)
        if unknown:
            parser.error(f"--only: unknown {sorted(unknown)}; valid: {', '.join(GROUPS)}")
    if args.runs is not None and args.runs < 1:
        parser.error(f"--runs must be >= 1, got {args.runs}")
    return args


def choose_venvs(which: str, results: Results) -> list[Venv]:
    venvs: list[Venv] = []
    for name, make in (("ros", project_venv), ("plain", plain_venv)):
        if which not in (name, "both"):
            continue
        venv = make()
        if isinstance(venv, str):
            results.skip("all", name, f"{name} venv", venv)
        else:
            venvs.append(venv)
    return venvs


def run(args: argparse.Namespace) -> Results:
    config = QUICK if args.quick else FULL
    if args.runs is not None:
        config = Config(**{**asdict(config), "runs": args.runs})
    groups = set(args.only.split(",")) if args.only else set(DEFAULT_GROUPS)
    if "startup" in groups:
        groups.add("memory")  # measured in the same runs
    results = Results()
    results.meta = {
        "mode": config.mode,
        "config": asdict(config),
        "when": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "host": platform.node(),
        "cpus": os.cpu_count(),
        "kernel": platform.release(),
        "python": platform.python_version(),
        "git": git_describe(),
        "loadavg_before": list(os.getloadavg()),
    }
    pr.become_subreaper()
    venvs = choose_venvs(args.venv, results)
    results.meta["venvs"] = {v.name: v.about for v in venvs}
    tmp = Path(tempfile.mkdtemp(prefix="mlaunch-bench-"))
    bench = Bench(config, venvs, tmp, results, reference=not args.no_reference)
    output_floors: dict[str, list[dict[str, float]]] = {}
    try:
        for venv in venvs:
            print(f"measuring in the {venv.name} venv ...", file=sys.stderr, flush=True)
            if "importtime" in groups:
                bench.importtime(venv)
            if "profile" in groups:
                bench.profile(venv)
            if "startup" in groups:
                bench.startup(venv)
            if "print" in groups:
                bench.print_cases(venv)
            if "plancache" in groups:
                bench.plan_cache(venv)
            if "output" in groups:
                bench.output(venv, output_floors)
        ros = next((v for v in venvs if v.name == "ros"), None)
        if "sim" in groups and ros is not None:
            with ros_domain(args.ros_domain) as domain:
                bench.sim(ros, domain)
        if "autoware" in groups:
            if ros is None:
                results.skip("autoware", "ros", "Autoware tree", "needs the project venv (rclpy)")
            else:
                with ros_domain(args.ros_domain) as domain:
                    bench.autoware(ros, domain)
        if "fleet" in groups and ros is not None:
            with ros_domain(args.ros_domain) as domain:
                bench.fleet(ros, domain)
    finally:
        pr.kill_descendants()
        if args.keep_temp:
            print(f"generated files kept in {tmp}", file=sys.stderr)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    results.meta["loadavg_after"] = list(os.getloadavg())
    return results


def git_describe() -> str:
    done = subprocess.run(
        ["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    )
    return done.stdout.strip()


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.readme:
        try:
            render_readme(Path(args.readme))
        except (OSError, ValueError, KeyError, BenchError) as e:
            print(f"benchmarks/run.py --readme: {e}", file=sys.stderr)
            return 1
        print(f"README.md: figures table written from {args.readme}")
        return 0
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        # Started in the background by a shell: children would inherit SIGINT ignored, and
        # the shutdown benchmark relies on the default action in the floor's children.
        signal.signal(signal.SIGINT, signal.default_int_handler)
    started = time.perf_counter()
    results = run(args)
    results.meta["harness_seconds"] = round(time.perf_counter() - started, 1)
    sys.stdout.write(format_table(results))
    document = json.dumps(results.to_json(), indent=2)
    if args.json == "-":
        sys.stdout.write(document + "\n")
    else:
        target = Path(args.json) if args.json else default_json_path(results.meta["mode"])
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(document + "\n")
        print(f"\nJSON: {target}")
    return 0


def default_json_path(mode: str) -> Path:
    return HERE / "results" / f"{mode}-{time.strftime('%Y%m%d-%H%M%S')}.json"


if __name__ == "__main__":
    sys.exit(main())
