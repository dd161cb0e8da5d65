"""The ``autoware`` group of benchmarks/run.py: Autoware's planning_simulator tree (the fixture of
``autoware_tree.py``: 55 processes, 53 composable nodes) started by mlaunch and by the reference
ros2 launch, alternating, in one run.

Every fixture process says on a FIFO that it runs (``p``), every container each component it
loaded (``l``); *everything up* is the moment the last of the 55 + 53 lines arrived. The harness
(the subreaper of all it starts) reads the process tree under it every ``POLL_S``: the fixture's
processes (the recorders' ``sleep``, the containers) are the launch's, ``xacro`` is the tree's
own command, everything else is the launcher: mlaunch or ros2 launch, and its helpers (mlaunch's
guard, anything it starts to talk to the graph). Figures per run:

- ``up``: exec of the launcher to everything up;
- ``cpu``: the launcher's CPU (user + system) until everything is up: its own, its reaped
  children's (ros2 launch runs the tree's xacro as a process, mlaunch runs it in-process), and
  each helper's;
- ``peak``: the sum of the peak RSS (VmHWM) of the launcher and each helper, the launcher's
  read once everything is up and again after the shutdown began (its peak may come later);
- ``shutdown``: SIGINT to the launcher until it and every process below it are gone.

``--print`` of the tree is timed too (wall and CPU of the whole command, ``python -c pass`` as
its floor).
"""

from __future__ import annotations

import os
import select
import shutil
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import autoware_tree as fixture
import probes as pr
from probes import BenchError

POLL_S = 0.05
RCLPY = ", loads through rclpy (MLAUNCH_LOADER=rclpy)"  # the variant of the launcher before
UP_TIMEOUT_S = 300.0  # ros2 launch takes ~15 s to resolve the tree on a quiet 2-core machine
STOP_TIMEOUT_S = 60.0


@dataclass
class Sample:
    """One start of the tree by one launcher."""

    up: float
    cpu: float
    peak_mb: float
    shutdown: float
    helpers: dict[str, float] = field(
        default_factory=dict
    )  # what each launcher-side process peaked at


@dataclass
class Seen:
    """What the last poll read of one process under the harness."""

    argv: list[str]
    ppid: int
    cpu: float  # own + reaped children's, seconds
    hwm_mb: float


def _stat(pid: int) -> tuple[int, float] | None:
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return None
    ticks = sum(int(x) for x in fields[11:15])  # utime stime cutime cstime
    return int(fields[1]), ticks / pr.CLK_TCK


def _argv(pid: int) -> list[str]:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return [a.decode(errors="replace") for a in f.read().split(b"\0") if a]
    except OSError:
        return []


def _hwm(pid: int) -> float:
    try:
        return pr.vm_hwm_mb(pid)
    except (OSError, BenchError):
        return 0.0


def descendants(root: int) -> list[int]:
    """Every live process below ``root`` (the engine's walk of /proc/PID/task/*/children)."""
    from mlaunch.engine.proctable import tree

    return [info.pid for info in tree(root)]


def is_fixture(argv: Sequence[str], prefix: Path) -> bool:
    """A process of the launch itself: a recorder (before or after its exec), a container."""
    if not argv:
        return True  # a zombie: nothing left to read
    name = os.path.basename(argv[0])
    if name == "sleep" or any(a.endswith("autoware_container.py") for a in argv[:3]):
        return True
    return name == "sh" and len(argv) > 1 and argv[1].startswith(str(prefix / "lib"))


def is_tree_command(argv: Sequence[str]) -> bool:
    """The tree's ``$(command xacro ...)``: both launchers run it."""
    return any(os.path.basename(a) == "xacro" for a in argv[:2])


class Watch:
    """Polls the processes under the harness: the launcher's side, with CPU and peak RSS."""

    def __init__(self, launcher: int, prefix: Path) -> None:
        self.launcher = launcher
        self.prefix = prefix
        self.me = os.getpid()
        self.seen: dict[int, Seen] = {}

    def poll(self) -> None:
        launcher_argv = _argv(self.launcher)
        for pid in [self.launcher, *descendants(self.me)]:
            argv = launcher_argv if pid == self.launcher else _argv(pid)
            if pid != self.launcher and (
                argv == launcher_argv  # forked, not yet exec'd: the child it will be
                or is_fixture(argv, self.prefix)
                or is_tree_command(argv)
            ):
                continue
            stat = _stat(pid)
            if stat is None:
                continue
            ppid, cpu = stat
            self.seen[pid] = Seen(argv, ppid, cpu, max(_hwm(pid), self._hwm_seen(pid)))

    def _hwm_seen(self, pid: int) -> float:
        old = self.seen.get(pid)
        return old.hwm_mb if old else 0.0

    def cpu(self) -> float:
        """The launcher's CPU with its reaped children's, and each helper's not counted there."""
        live = set(descendants(self.me)) | {self.launcher}
        total = 0.0
        for pid, seen in self.seen.items():
            if pid != self.launcher and pid not in live and seen.ppid == self.launcher:
                continue  # reaped by the launcher: in its cutime already
            total += seen.cpu
        return total

    def peaks(self) -> dict[str, float]:
        named: dict[str, float] = {}
        for pid, seen in self.seen.items():
            label = "launcher" if pid == self.launcher else _label(seen.argv)
            named[label] = named.get(label, 0.0) + seen.hwm_mb
        return named


def _label(argv: Sequence[str]) -> str:
    """A helper's name, the same in every run (a process title's ``[run PID]`` left out)."""
    if len(argv) == 1 and " [" in argv[0]:
        return argv[0].split(" [", 1)[0]
    words = [a for a in argv[:4] if not a.startswith("-")]
    for word in words[1:]:
        if "mlaunch" in word or word.endswith(".py"):
            return os.path.basename(word)
    return os.path.basename(words[0]) if words else "?"


class Lines:
    """The fixture's FIFO: counts ``p`` (a process runs) and ``l`` (a component loaded)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        os.mkfifo(path)
        self.rfd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        # Our own write end: the containers open and close it per line, so without it the
        # reader would see EOF between their lines.
        self.wfd = os.open(path, os.O_WRONLY)
        self.processes = 0
        self.loads = 0
        self.rest = b""

    def read(self, timeout: float) -> None:
        ready, _, _ = select.select([self.rfd], [], [], max(timeout, 0.0))
        if not ready:
            return
        try:
            data = os.read(self.rfd, 65536)
        except BlockingIOError:
            return
        *lines, self.rest = (self.rest + data).split(b"\n")
        for line in lines:
            if line.startswith(b"p "):
                self.processes += 1
            elif line.startswith(b"l "):
                self.loads += 1

    def close(self) -> None:
        for fd in (self.rfd, self.wfd):
            os.close(fd)
        self.path.unlink(missing_ok=True)


def start_tree(
    argv: Sequence[str], env: Mapping[str, str], tree: fixture.Tree, tmp: Path, out: Path
) -> Sample:
    """One start of the tree by ``argv``: up, CPU, peak memory, shutdown; all ended after."""
    lines = Lines(tmp / "fixture.fifo")
    env = {**env, fixture.FIFO_VARIABLE: str(lines.path)}
    with open(out, "wb") as sink:
        proc = pr.launch(argv, env, stdout=sink.fileno(), stderr=subprocess.STDOUT)
    try:
        watch = Watch(proc.pid, tree.prefix)
        deadline = proc.started + UP_TIMEOUT_S
        want = (fixture.PROCESSES, fixture.COMPOSABLES)
        next_poll = 0.0
        while lines.processes < want[0] or lines.loads < want[1]:
            now = time.perf_counter()
            if now > deadline:
                raise BenchError(
                    f"not up after {UP_TIMEOUT_S:.0f} s: {lines.processes} processes,"
                    f" {lines.loads} components"
                )
            if proc.poll_exit():
                raise BenchError(f"the launcher exited ({proc.returncode}) before all was up")
            if now >= next_poll:
                watch.poll()
                next_poll = now + POLL_S
            lines.read(min(POLL_S, next_poll - now))
        up = time.perf_counter() - proc.started
        watch.poll()
        cpu = watch.cpu()
        sent = time.perf_counter()
        os.kill(proc.pid, signal.SIGINT)
        watch.poll()  # the launcher's peak may come with the shutdown: read once more
        proc.reap(sent + STOP_TIMEOUT_S)
        assert proc.exited_at is not None
        gone = max(proc.exited_at, pr.wait_no_children(sent + STOP_TIMEOUT_S, poll=0.005))
        peaks = watch.peaks()
        return Sample(up, cpu, sum(peaks.values()), gone - sent, peaks)
    except BenchError as exc:
        tail = out.read_text(errors="replace").strip().splitlines()[-3:]
        raise BenchError(f"{exc}; output: {' | '.join(tail)}") from None
    finally:
        proc.kill()
        pr.kill_descendants()
        lines.close()


def reference_env(base: Mapping[str, str], work: Path) -> dict[str, str] | str:
    """The reference ros2 launch's environment (tests/reference.py says where it is built) with
    this venv's composition_interfaces over its import shim, as the conformance tests run it;
    a reason where it is not built."""
    conformance = str(fixture.REPO / "tests" / "conformance")
    if conformance not in sys.path:
        sys.path.append(conformance)  # where the conformance tests keep both helpers
    import components
    import harness

    env = harness.reference_environ()
    if env is None:
        return harness.reference.MISSING  # type: ignore[no-any-return]
    overlay = components.interfaces_overlay(work)
    env["PYTHONPATH"] = overlay["PYTHONPATH"]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(
        p for p in (env.get("LD_LIBRARY_PATH"), overlay["LD_LIBRARY_PATH"]) if p
    )
    for name in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_LOG_DIR", "HOME"):
        if name in base:
            env[name] = base[name]
    return env


def rusage(argv: Sequence[str], env: Mapping[str, str], timeout: float = 120.0) -> Usage:
    """Wall time, CPU (its own and its reaped children's) of ``argv``, which must succeed, and
    the peak RSS it says last on stderr (``VmHWM: N kB``, what ``HWM_LINE`` prints), if it does.

    Not ru_maxrss: a child forked from the harness starts with the harness's RSS (~30 MB), and
    ru_maxrss keeps that across the exec.
    """
    started = time.perf_counter()
    proc = subprocess.Popen(
        list(argv),
        env=dict(env),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    try:
        assert proc.stderr is not None
        err = proc.stderr.read()  # until it exits (or closes stderr)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    finally:
        if proc.returncode is None:
            proc.kill()
            proc.wait()
        if proc.stderr is not None:
            proc.stderr.close()
    wall = time.perf_counter() - started
    lines = err.decode(errors="replace").strip().splitlines()
    if proc.returncode != 0 or wall > timeout:
        raise BenchError(f"{' '.join(argv[:3])}: exit {proc.returncode}: {' '.join(lines[-1:])}")
    said = [line.split()[1] for line in lines if line.startswith("VmHWM:")]
    peak = int(said[-1]) * 1024 / 1e6 if said else 0.0
    return Usage(wall, usage.ru_utime + usage.ru_stime, peak)


# Appended to a part's code: its own peak RSS, on stderr.
HWM_LINE = (
    "\nimport sys as _s\n"
    "_s.stderr.write(next(l for l in open('/proc/self/status') if l.startswith('VmHWM')))"
)


@dataclass(frozen=True)
class Usage:
    wall: float
    cpu: float
    peak_mb: float


@dataclass
class Figure:
    """One row of the table (benchmarks/run.py makes it a Row)."""

    name: str
    unit: str
    samples: list[float]
    floor_name: str = ""
    floor_samples: list[float] = field(default_factory=list)
    target: float | None = None
    note: str = ""
    reference_samples: list[float] = field(default_factory=list)  # ros2 launch's, same run


# What the ROS wheels' .pth hook sets before it re-execs an interpreter.
HOOK_VARIABLES = ("_ROS_WHEELS_BOOTSTRAP_COMPLETE", "LD_LIBRARY_PATH")

# What each part of a launcher's memory and CPU is, measured alone (python -c CODE).
PARTS = {
    "the interpreter": "pass",
    "import rclpy (+ rclpy.node, composition_interfaces)": (
        "import rclpy, rclpy.node, composition_interfaces.srv"
    ),
    "rclpy: init + one node with a LoadNode client (the DDS participant)": (
        "import rclpy, rclpy.node, composition_interfaces.srv as s\n"
        "rclpy.init()\n"
        "n = rclpy.node.Node('_mlaunch_bench_part', start_parameter_services=False,"
        " enable_rosout=False)\n"
        "n.create_client(s.LoadNode, '/bench/_container/load_node')\n"
        "n.destroy_node(); rclpy.shutdown()"
    ),
    # As mlaunch's LoadNode driver makes it (mlaunch.parts.lean): the floor of its rclpy side.
    "the same, lean (UDPv4 only, two malloc arenas: the launcher's own participant)": (
        "from mlaunch.parts.lean import lean_participant, limit_arenas\n"
        "limit_arenas()\n"
        "import rclpy, rclpy.node, composition_interfaces.srv as s\n"
        "rclpy.init()\n"
        "with lean_participant():\n"
        "    n = rclpy.node.Node('_mlaunch_bench_part', start_parameter_services=False,"
        " enable_rosout=False)\n"
        "n.create_client(s.LoadNode, '/bench/_container/load_node')\n"
        "n.destroy_node(); rclpy.shutdown()"
    ),
    # What the launcher's loads cost now (mlaunch.parts.rtps): no rclpy at all.
    "RTPS: a participant with a LoadNode client (mlaunch's default, no rclpy)": (
        "import os, time\n"
        "from mlaunch.parts.loadnode_links import RtpsLink\n"
        "from mlaunch.parts.rtps import discovery_range\n"
        "link = RtpsLink(int(os.environ.get('ROS_DOMAIN_ID') or 0),"
        " discovery_range(os.environ) or 'SUBNET')\n"
        "link.prepare(); link.client('/bench/_container/load_node', 'LoadNode')\n"
        "time.sleep(0.5)\n"  # its first announcements and what answers them
        "link.close()"
    ),
}


def measure(
    runs: int,
    mlaunch: Path,
    python: Path,
    env: Mapping[str, str],
    tmp: Path,
    say: Callable[[str], None],
    cache: Path = fixture.CACHE,
) -> list[Figure] | str:
    """The group's figures, or why it cannot run (the sources or the reference are absent).

    ``env``: the measured environment, with a private ROS_DOMAIN_ID. Run 0 is a warm-up.
    """
    sources = cache / "sources"
    if not fixture.have_sources(sources):
        return (
            f"no Autoware sources in {sources}: run 'benchmarks/autoware_tree.py' once (it"
            " downloads them; --git DIR or --sources DIR take a local copy)"
        )
    try:
        tree = fixture.build(sources, cache)
    except fixture.FixtureError as exc:
        return f"the fixture cannot be built: {exc}"
    reference = reference_env(env, tmp)
    if isinstance(reference, str):
        return reference
    ours = tree.environ(dict(env))
    # The harness turns the plan cache off for the other groups (run.py's measured
    # environment); here it is on as a user has it, and --no-cache (or cold) turns it off.
    ours.pop("MLAUNCH_NO_CACHE", None)
    theirs = tree.environ(reference)
    ros2 = shutil.which("ros2", path=theirs["PATH"])
    if ros2 is None:
        return "the reference environment has no ros2 command"
    launch = [str(tree.launch_file), *tree.arguments]
    # mlaunch three times a run: as a user starts it (the plan cache on: from run 1 on, the
    # plan the warm-up stored), resolving the files again (--no-cache), and with the loads
    # through rclpy as before the RTPS client (MLAUNCH_LOADER=rclpy, the plan cache on).
    cold = {**ours, "MLAUNCH_NO_CACHE": "1"}
    through_rclpy = {**ours, "MLAUNCH_LOADER": "rclpy"}
    ml: dict[str, list[Sample]] = {"": [], ", --no-cache": [], RCLPY: []}
    ref: list[Sample] = []
    for i in range(runs + 1):
        say(f"autoware: run {i} of {runs} (0 is the warm-up): ros2 launch ...")
        one_ref = start_tree([ros2, "launch", *launch], theirs, tree, tmp, tmp / "ros2.out")
        say(f"autoware: run {i}: mlaunch, mlaunch --no-cache ...")
        warm = start_tree([str(mlaunch), *launch], ours, tree, tmp, tmp / "mlaunch.out")
        fresh = start_tree([str(mlaunch), *launch], cold, tree, tmp, tmp / "mlaunch.out")
        old = start_tree([str(mlaunch), *launch], through_rclpy, tree, tmp, tmp / "mlaunch.out")
        if i:
            ref.append(one_ref)
            ml[""].append(warm)
            ml[", --no-cache"].append(fresh)
            ml[RCLPY].append(old)
    figures = [
        Figure(
            "planning_simulator: 55 processes and 53 components up",
            "s",
            [s.up for s in ml[""]],
            reference_samples=[s.up for s in ref],
        )
    ]
    for variant, samples in ml.items():
        figures += tree_figures(variant, samples, ref, targets=variant != RCLPY)
    figures += print_figures(runs, mlaunch, python, launch, ours)
    figures += part_figures(runs, python, mlaunch, launch, ours)
    return figures


def tree_figures(
    variant: str, ml: Sequence[Sample], ref: Sequence[Sample], targets: bool = True
) -> list[Figure]:
    """The launcher's CPU and memory (with their ratios to ros2 launch's) and Ctrl-C; the
    issue's targets on the ratios unless ``targets`` is False (a comparison, not a goal)."""

    def both(name: str, attr: str, unit: str, note: str = "") -> Figure:
        return Figure(
            name + variant,
            unit,
            [getattr(s, attr) for s in ml],
            note=note,
            reference_samples=[getattr(s, attr) for s in ref],
        )

    def ratio(name: str, attr: str, target: float) -> Figure:
        pairs = zip(ml, ref, strict=True)
        values = [getattr(m, attr) / getattr(r, attr) for m, r in pairs]
        return Figure(
            name + variant + ", mlaunch / ros2 launch",
            "x",
            values,
            target=target if targets else None,
        )

    return [
        both("launcher CPU until all up", "cpu", "s"),
        ratio("launcher CPU until all up", "cpu", 0.05),
        both("peak RSS, launcher and its helpers", "peak_mb", "MB", _helpers_note(ml, ref)),
        ratio("peak RSS", "peak_mb", 0.7),
        both("SIGINT until all gone", "shutdown", "s"),
    ]


def _helpers_note(ml: Sequence[Sample], ref: Sequence[Sample]) -> str:
    def medians(samples: Sequence[Sample]) -> str:
        labels = sorted({k for s in samples for k in s.helpers})
        return ", ".join(
            f"{k} {statistics.median(s.helpers.get(k, 0.0) for s in samples):.1f} MB"
            for k in labels
        )

    return f"peak RSS by process (medians): mlaunch: {medians(ml)}; ros2 launch: {medians(ref)}"


def print_figures(
    runs: int, mlaunch: Path, python: Path, launch: list[str], env: Mapping[str, str]
) -> list[Figure]:
    """``mlaunch --print`` of the tree (wall and CPU), ``python -c pass`` its floor."""
    printed: dict[str, list[Usage]] = {"": [], ", --no-cache": []}
    floor: list[Usage] = []
    for i in range(runs + 1):
        one = rusage([str(mlaunch), "--print", *launch], env)
        again = rusage([str(mlaunch), "--print", "--no-cache", *launch], env)
        bare = rusage([str(python), "-c", "pass"], env)
        if i:
            printed[""].append(one)
            printed[", --no-cache"].append(again)
            floor.append(bare)
    figures: list[Figure] = []
    for variant, usages in printed.items():
        figures += [
            Figure(f"--print of the tree{variant}", "s", [u.wall for u in usages],
                   "python -c pass", [u.wall for u in floor], target=0.5),
            Figure(f"--print of the tree{variant}, CPU", "s", [u.cpu for u in usages],
                   "python -c pass", [u.cpu for u in floor]),
        ]  # fmt: skip
    return figures


def part_figures(
    runs: int, python: Path, mlaunch: Path, launch: list[str], env: Mapping[str, str]
) -> list[Figure]:
    """What each part costs alone: peak RSS and CPU of the interpreter, of resolving the tree
    (``--print``, with xacro, which mlaunch runs in-process), of importing rclpy, of one node
    (the DDS participant)."""
    # Without the ROS wheels' re-exec (the harness's own environment has run it): each part
    # alone, in one interpreter.
    env = {**env, **{k: os.environ[k] for k in HOOK_VARIABLES if k in os.environ}}
    env.pop("MLAUNCH_NO_CACHE", None)  # the resolving part says --no-cache itself
    codes = dict(PARTS)
    codes["resolve the tree (mlaunch --print --no-cache, xacro in-process)"] = (
        f"from mlaunch.cli import main\nmain({['--print', '--no-cache', *launch]!r})"
    )
    codes["the plan of the tree from the cache (mlaunch --print)"] = (
        f"from mlaunch.cli import main\nmain({['--print', *launch]!r})"
    )
    commands = {name: [str(python), "-c", code + HWM_LINE] for name, code in codes.items()}
    figures: list[Figure] = []
    for name, argv in commands.items():
        usages = [rusage(argv, env) for _ in range(runs + 1)][1:]
        figures.append(Figure(f"part: {name}, peak RSS", "MB", [u.peak_mb for u in usages]))
        figures.append(Figure(f"part: {name}, CPU", "s", [u.cpu for u in usages]))
    return figures
