"""``mlaunch test FILE [name:=value ...] [options]``: a CI smoke run of a launch file.

It starts the launch exactly as ``mlaunch FILE`` would, waits until the system is *ready*,
holds it (``--hold S``, 3 s by default) watching for crashes, shuts it down and exits 0; anything
else exits 1 with a table of what was expected and what was seen, and the last lines of output
of the processes involved (``--junit FILE`` writes the same as JUnit XML).

Ready means, by default:
  - every process of the launch started and is still running;
  - every Node with a name is in the ROS graph under its fully qualified name;
  - every lifecycle node is ``active``;
  - with use_sim_time (``--use-sim-time``, ``use_sim_time:=true``, a SetParameter or a node's
    own parameter), ``/clock`` is advancing;
and at the end, every process stopped within its stop ladder (none needed SIGKILL). A process
that exits with a failure (non-zero status, or a signal) before the end fails the test; one that
exits 0 is a one-shot (a spawner, a loader) and fine, unless it was started with respawn: a
respawning process that exits fails even with status 0, and ``--allow-exit LABEL`` lets it
(label or base name) finish with status 0. At the end, a process that started less than
STARTUP_GRACE seconds ago is given the rest of that time before the stop signals, so it is not
interrupted half-way through its imports. Processes started later by
timers or event handlers are watched from when they start.

More expectations, from the command line (each has the overall ``--timeout`` as deadline unless
``--within S`` follows it):
  --expect-topic /scan[:RATE_HZ]     messages arrive (at >= 90% of RATE_HZ, when given)
  --expect-service /map_server/load_map
  --expect-node /robot1/amcl
  --expect-lifecycle /robot1/amcl[:STATE]   (default active; replaces the default check)
  --expect-output 'LABEL:REGEX' | 'REGEX'   a line of output (LABEL: a process label like
                                     talker-1 or its base name talker) matches REGEX
  --expect-clock /clock              simulated time advances (also without use_sim_time)
  --expect 'KIND TARGET [within S]'  the same in one string (KIND: topic, service, node,
                                     lifecycle, output, clock)
or from the launch file:
  - any launch configuration whose name starts with ``mlaunch_expect`` holds one expectation
    as 'KIND TARGET [within S]', e.g. in YAML
    ``- let: {name: mlaunch_expect_scan, value: "topic /scan:10 within 15"}``, in XML
    ``<let name="mlaunch_expect_scan" value="topic /scan:10"/>`` (it must be set where the
    top level of the launch sees it: at the top level, or in an included file, not in a group);
  - in Python, ``mlaunch.smoke.Expect(topic="/scan", rate=10.0, within=15)`` (or
    ``service=``, ``node=``, ``lifecycle=`` with ``state=``, ``output=`` with ``process=``).
A normal ``mlaunch FILE`` run ignores both.

Exit status: 0 ready (and held, and stopped cleanly); 1 an expectation failed; 2 bad command
line or launch file; 128+N interrupted by signal N.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
import threading
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from mlaunch.errors import EXIT_FAILURE, EXIT_OK, LaunchFileError, UsageError
from mlaunch.launch.actions import Action
from mlaunch.launch.substitutions import perform
from mlaunch.run.events import Event, Exited, Output, Started
from mlaunch.run.plan import Note

if TYPE_CHECKING:
    from mlaunch.ros.handoff import SharedGraph
    from mlaunch.ros.lifecycle import LifecycleManager, Outcome
    from mlaunch.run.lifeline import Lifeline
    from mlaunch.run.plan import Plan, ProcessSpec
    from mlaunch.run.process import Process
    from mlaunch.run.resolve import Resolver
    from mlaunch.run.supervisor import Supervisor

_HELP = __doc__ or ""
DEFAULT_TIMEOUT = 30.0
# Held after ready so a node that crashes a few seconds in is caught (--hold 0 skips it).
DEFAULT_HOLD = 3.0
# At the end, the youngest process is given up to this long since its start before the stop
# signals: SIGINT during a Python node's imports leaves a traceback in a passing run.
STARTUP_GRACE = 2.0
RING_LINES = 20
# A topic given with a rate passes at this fraction of it (publishers jitter, CI machines lag).
RATE_TOLERANCE = 0.9
# The graph is looked at this often; deadlines are checked this often.
GRAPH_PERIOD = 0.2
TICK = 0.1
# Waiting for a lifecycle node's get_state answer while checking (it is asked again later).
STATE_QUERY_TIMEOUT = 1.0
CONFIG_PREFIX = "mlaunch_expect"
KINDS = ("topic", "service", "node", "lifecycle", "output", "clock")
HELP = {
    "topic": "/scan[:RATE_HZ]: messages arrive (at >= 90%% of RATE_HZ)",
    "service": "/name: the service is offered",
    "node": "/ns/name: the node is in the ROS graph",
    "lifecycle": "/ns/name[:STATE]: the managed node is in STATE (active)",
    "output": "'LABEL:REGEX' or 'REGEX': a line of output matches",
    "clock": "/clock: simulated time advances (implied by use_sim_time)",
}
GRAPH_KINDS = frozenset({"topic", "service", "node", "lifecycle", "clock"})
LIFECYCLE_STATES = ("unconfigured", "inactive", "active", "finalized")
STATUS_MARKS = {"met": "ok", "failed": "FAIL", "skipped": "--", "pending": "--"}
_WITHIN = re.compile(r"^(?P<body>.*?)\s+within\s+(?P<seconds>[0-9]+(?:\.[0-9]*)?)\s*s?$")
_ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


# --- expectations ---------------------------------------------------------------------------------


@dataclass
class Expectation:
    """One thing that must hold for the launch to count as ready, and what was seen of it."""

    kind: str  # process, node, lifecycle, topic, service, output, clock, shutdown
    target: str
    origin: str = "default"
    within: float | None = None  # seconds from the start; None: the overall --timeout
    rate: float | None = None
    state: str = "active"
    process: str | None = None  # output: only this process (label or base name)
    regex: re.Pattern[str] | None = None
    labels: list[str] = field(default_factory=list)  # processes whose output explains it
    status: str = "pending"  # pending, met, failed
    seen: str = "not checked yet"
    at: float | None = None  # seconds from the start when it was met or failed

    def describe(self) -> str:
        if self.kind == "process":
            return f"process {self.target} starts and keeps running"
        if self.kind == "node":
            return f"node {self.target} is in the ROS graph"
        if self.kind == "lifecycle":
            return f"lifecycle node {self.target} is {self.state}"
        if self.kind == "topic":
            if self.rate is None:
                return f"topic {self.target} publishes"
            return f"topic {self.target} publishes at {self.rate:g} Hz"
        if self.kind == "service":
            return f"service {self.target} is offered"
        if self.kind == "output":
            where = f"{self.process} " if self.process else ""
            return f"output of {where or 'any process '}matches /{self.target}/"
        if self.kind == "clock":
            return "/clock advances (use_sim_time)"
        return "every process stops within its stop ladder (no SIGKILL)"

    def key(self) -> tuple[str, str]:
        return (self.kind, self.target)


def parse_spec(text: str, origin: str) -> Expectation:
    """'KIND TARGET [within S]' (the launch-file and --expect form) -> Expectation."""
    text = text.strip()
    within = None
    match = _WITHIN.match(text)
    if match:
        text, within = match["body"].strip(), float(match["seconds"])
    kind, _, target = text.partition(" ")
    if kind not in KINDS or not target.strip():
        raise UsageError(
            f"expectation {text!r} ({origin}) is not 'KIND TARGET [within SECONDS]'"
            f" with KIND one of {', '.join(KINDS)}, e.g. 'topic /scan:10 within 15'"
        )
    expectation = parse_target(kind, target.strip(), origin)
    expectation.within = within
    return expectation


def parse_target(kind: str, target: str, origin: str) -> Expectation:
    """The TARGET of one kind of expectation (what follows --expect-KIND)."""
    if kind == "topic":
        name, sep, rate_text = target.rpartition(":")
        if not sep:
            return Expectation("topic", _absolute(target, "topic", origin), origin)
        return Expectation(
            "topic", _absolute(name, "topic", origin), origin, rate=_rate(rate_text, target, origin)
        )
    if kind in ("service", "node"):
        return Expectation(kind, _absolute(target, kind, origin), origin)
    if kind == "lifecycle":
        name, sep, state = target.partition(":")
        state = state.strip() if sep else "active"
        if state not in LIFECYCLE_STATES:
            raise UsageError(
                f"lifecycle expectation {target!r} ({origin}): state {state!r} is not one of"
                f" {', '.join(LIFECYCLE_STATES)}"
            )
        return Expectation("lifecycle", _absolute(name, "node", origin), origin, state=state)
    if kind == "output":
        return Expectation("output", target, origin)
    if kind == "clock":
        return Expectation("clock", _absolute(target, "topic", origin), origin)
    raise UsageError(f"unknown expectation kind {kind!r}; valid: {', '.join(KINDS)}")


def _absolute(name: str, what: str, origin: str) -> str:
    name = name.strip()
    if not name or any(c.isspace() for c in name) or ":" in name:
        raise UsageError(f"{what} name {name!r} ({origin}) is not a ROS name like '/robot1/scan'")
    return name if name.startswith("/") else f"/{name}"


def _rate(text: str, target: str, origin: str) -> float:
    try:
        rate = float(text)
    except ValueError:
        rate = -1.0
    if not rate > 0 or rate == float("inf"):
        raise UsageError(
            f"topic expectation {target!r} ({origin}): rate {text!r} is not a positive number"
            " of Hz (write /scan:10)"
        )
    return rate


# --- the launch-file side -------------------------------------------------------------------------


@dataclass
class ExpectStep(Note):
    """Plan step of an Expect action (a Note: the smoke run reads it from the plan)."""

    origin: str = ""  # Step is a plain class: a dataclass subclass names its field itself
    expectation: Expectation | None = None


class Expect(Action):
    """An expectation for ``mlaunch test``, written in a Python launch file.

    Exactly one of ``topic`` (with ``rate`` in Hz), ``service``, ``node``, ``lifecycle`` (with
    ``state``, default active) or ``output`` (a regex, with ``process``: a label or base name)
    is given; ``within`` overrides the run's ``--timeout`` for it.
    """

    def __init__(
        self,
        *,
        topic: Any = None,
        rate: float | None = None,
        service: Any = None,
        node: Any = None,
        lifecycle: Any = None,
        state: str = "active",
        output: Any = None,
        process: Any = None,
        within: float | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        given = {
            k: v
            for k, v in (
                ("topic", topic),
                ("service", service),
                ("node", node),
                ("lifecycle", lifecycle),
                ("output", output),
            )
            if v is not None
        }
        if len(given) != 1:
            raise LaunchFileError(
                "Expect takes exactly one of topic=, service=, node=, lifecycle=, output="
                f" (got {', '.join(given) or 'none'})",
                where=self.origin,
            )
        ((self.kind, self.target),) = given.items()
        self.rate, self.state, self.process, self.within = rate, state, process, within

    def execute(self, resolver: Resolver) -> None:
        ctx = resolver.context
        target = perform(ctx, self.target)
        where = f"Expect at {self.origin}"
        if self.kind == "topic" and self.rate is not None:
            target = f"{target}:{self.rate}"
        elif self.kind == "lifecycle":
            target = f"{target}:{self.state}"
        elif self.kind == "output" and self.process is not None:
            target = f"{perform(ctx, self.process)}:{target}"
        try:
            expectation = parse_target(self.kind, target, where)
        except UsageError as e:
            raise LaunchFileError(str(e), where=self.origin) from None
        expectation.within = self.within
        resolver.add(ExpectStep(origin=self.origin, expectation=expectation))


class _CollectConfigurations(Action):
    """Appended after the launch file by ``mlaunch test``: reads mlaunch_expect* and sim time."""

    def __init__(self) -> None:
        super().__init__()
        self.found: list[Expectation] = []
        self.use_sim_time = False

    def execute(self, resolver: Resolver) -> None:
        configs = resolver.context.launch_configurations
        for name in sorted(configs):
            if name.startswith(CONFIG_PREFIX):
                origin = f"launch configuration {name}"
                self.found.append(parse_spec(str(configs[name]), origin))
        for entry in configs.get("global_params", ()) or ():
            if isinstance(entry, tuple) and entry[0] == "use_sim_time":
                self.use_sim_time = _true(entry[1])


def _true(value: Any) -> bool:
    return value is True or str(value).strip().lower() in ("true", "1", "yes", "on")


# --- the command line -----------------------------------------------------------------------------


@dataclass
class Settings:
    """What ``mlaunch test`` adds to ``mlaunch FILE``'s options."""

    expectations: list[Expectation] = field(default_factory=list)
    timeout: float = DEFAULT_TIMEOUT
    hold: float = DEFAULT_HOLD
    junit: str | None = None
    allow_exit: list[str] = field(default_factory=list)


VALUE_FLAGS = (
    "--expect",
    "--expect-topic",
    "--expect-service",
    "--expect-node",
    "--expect-lifecycle",
    "--expect-output",
    "--within",
    "--timeout",
    "--hold",
    "--junit",
    "--allow-exit",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="mlaunch test",
        usage="mlaunch test FILE [name:=value ...] [options of mlaunch FILE] [test options]",
        description="Start a launch, wait until it is ready, hold it, stop it: exit 0 when"
        " every expectation held, 1 otherwise (with a table of expected vs seen).",
        # The docstring's reStructuredText quoting means nothing on a terminal.
        epilog=_HELP[_HELP.index("Ready means") :].replace("``", "")
        + "\nEvery option of 'mlaunch FILE' is accepted too (see mlaunch --help).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    group = parser.add_argument_group("expectations")
    for kind in KINDS:
        group.add_argument(
            f"--expect-{kind}",
            metavar=kind.upper(),
            action=_ExpectAction,
            const=kind,
            help=HELP[kind],
        )
    group.add_argument(
        "--expect",
        metavar="'KIND TARGET [within S]'",
        action=_ExpectAction,
        help="any of the above in one string",
    )
    group.add_argument(
        "--within",
        metavar="S",
        type=float,
        action=_WithinAction,
        help="the deadline (seconds from the start) of the expectation just before",
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=DEFAULT_TIMEOUT,
        metavar="S",
        help=f"deadline for everything to be ready (default {DEFAULT_TIMEOUT:g} s)",
    )
    parser.add_argument(
        "--hold",
        type=float,
        default=DEFAULT_HOLD,
        metavar="S",
        help=f"stay up S seconds after ready, watching for crashes (default {DEFAULT_HOLD:g};"
        " 0 skips it)",
    )
    parser.add_argument("--junit", metavar="FILE", help="write a JUnit XML report")
    parser.add_argument(
        "--allow-exit",
        action="append",
        default=[],
        metavar="LABEL",
        help="a respawning process (label or base name) that may still finish with status 0"
        " (repeatable; a process without respawn that exits 0 is a one-shot, fine anyway)",
    )
    return parser


class _ExpectAction(argparse.Action):
    def __call__(self, parser: Any, ns: Any, value: Any, option: str | None = None) -> None:
        items = getattr(ns, "expectations", None) or []
        if self.const is None:
            items.append(parse_spec(value, f"{option} {value!r}"))
        else:
            items.append(parse_target(self.const, value, f"{option} {value!r}"))
        ns.expectations = items


class _WithinAction(argparse.Action):
    def __call__(self, parser: Any, ns: Any, value: Any, option: str | None = None) -> None:
        items = getattr(ns, "expectations", None) or []
        if not items:
            raise UsageError("--within S follows an --expect-... option and sets its deadline")
        if not value > 0:
            raise UsageError(f"--within {value!r}: the deadline must be > 0 seconds")
        items[-1].within = value


def split_arguments(args: Sequence[str]) -> tuple[list[str], list[str]]:
    """(test options, everything else for mlaunch FILE's own parser)."""
    mine: list[str] = []
    rest: list[str] = []
    i = 0
    while i < len(args):
        arg = args[i]
        name = arg.split("=", 1)[0]
        if name in VALUE_FLAGS:
            mine.append(arg)
            if "=" not in arg:
                if i + 1 >= len(args):
                    raise UsageError(f"{arg} needs a value")
                mine.append(args[i + 1])
                i += 1
        elif arg in ("-h", "--help"):
            mine.append(arg)
        else:
            rest.append(arg)
        i += 1
    return mine, rest


def parse_settings(args: Sequence[str]) -> Settings:
    ns = build_parser().parse_args(list(args))
    for what, value in (("--timeout", ns.timeout), ("--hold", ns.hold)):
        if not value >= 0 or value == float("inf"):
            raise UsageError(f"{what} {value!r}: expected a number of seconds >= 0")
    if ns.timeout == 0:
        raise UsageError("--timeout 0: the deadline must be > 0 seconds")
    return Settings(
        expectations=list(getattr(ns, "expectations", None) or []),
        timeout=ns.timeout,
        hold=ns.hold,
        junit=ns.junit,
        allow_exit=list(ns.allow_exit),
    )


def main(args: Sequence[str]) -> int:
    """``mlaunch test ARGS``: through mlaunch's main, which prints errors and gives the status."""
    # Through the one main that prints errors and gives the status: this runs the subcommand
    # on its own (tests, a script), so it calls back up to the command line on purpose.
    from mlaunch import cli

    return cli.main(["test", *args])


def command(args: Sequence[str]) -> int:
    """``mlaunch test``'s work; errors go up to mlaunch.cli.main."""
    from mlaunch.options import parse_options
    from mlaunch.run import pipeline

    args = list(args)
    from mlaunch.launch_testing.launch_test import is_launch_test_file

    if any(is_launch_test_file(a) for a in args if not a.startswith("-")):
        # A launch_testing file (it defines generate_test_description): launch_test runs it.
        from mlaunch.launch_testing.launch_test import main as launch_test_main

        return launch_test_main(args, prog="mlaunch test")
    mine, rest = split_arguments(args)
    try:
        settings = parse_settings(mine)
        opts = parse_options(rest) if rest else None
    except SystemExit as e:  # argparse: --help (0) or a usage error (2), already printed
        return int(e.code or 0)
    if opts is None:
        raise UsageError("a launch file is needed: mlaunch test FILE [name:=value ...]")
    if opts.show_args or opts.print_plan:
        return pipeline.launch(opts, pipeline.standard_parts(opts))
    return run(opts, settings)


# --- running --------------------------------------------------------------------------------------


def run(opts: Any, settings: Settings) -> int:
    """Load, resolve, supervise with the smoke checks attached; report; the exit status."""
    from mlaunch.launch.actions import LaunchDescription
    from mlaunch.run import pipeline
    from mlaunch.run.lifeline import Lifeline
    from mlaunch.run.logfiles import make_run_log_dir

    with Lifeline() as life:  # signals, guard and marker from the first line of the launch on
        path, description = pipeline.load_target(opts)
        collector = _CollectConfigurations()
        log_dir = make_run_log_dir(os.environ)
        plan, options, labels = pipeline.resolve_for_run(
            opts,
            path,
            LaunchDescription([description, collector]),
            temp_dir=life.temp_dir,
            log_dir=log_dir,
        )
        # use_sim_time:=true is an ordinary launch argument; a file that declares it is
        # expected to run on simulated time, as --use-sim-time is.
        sim_time = bool(opts.use_sim_time) or _true(opts.arguments.get("use_sim_time", "false"))
        expectations = build_expectations(plan, settings, collector, sim_time)
        return supervise(opts, settings, plan, options, labels, log_dir, path, expectations, life)


def build_expectations(
    plan: Plan, settings: Settings, collector: _CollectConfigurations, use_sim_time: bool
) -> list[Expectation]:
    """Defaults from the plan, then the launch file's, then the command line's (later wins)."""
    specs = plan.processes()
    explicit = [s.expectation for s in plan.steps if isinstance(s, ExpectStep) and s.expectation]
    explicit += collector.found + settings.expectations
    out: dict[tuple[str, str], Expectation] = {}
    for spec in specs:
        out[("process", spec.label)] = Expectation("process", spec.label, labels=[spec.label])
    for spec in specs:
        fqn = spec.node.fully_qualified_name if spec.node is not None else None
        if spec.node is None or fqn is None:
            continue
        out.setdefault(("node", fqn), Expectation("node", fqn))
        if spec.node.lifecycle:
            out.setdefault(("lifecycle", fqn), Expectation("lifecycle", fqn))
    components: dict[str, str] = {}  # composable node -> its container (LoadComponents steps)
    for step in plan.steps:
        for name in getattr(step, "component_names", list)():
            components[name] = step.target  # type: ignore[attr-defined]
            out.setdefault(("node", name), Expectation("node", name))
    if use_sim_time or collector.use_sim_time or any(_sim_time_argv(s.argv) for s in specs):
        out[("clock", "/clock")] = Expectation("clock", "/clock")
    for expectation in explicit:
        out[expectation.key()] = expectation
    for expectation in out.values():
        _involve(expectation, specs)
        if expectation.kind == "node" and expectation.target in components:
            container = components[expectation.target]
            expectation.labels = [
                s.label for s in specs if s.node and s.node.fully_qualified_name == container
            ]
    found = list(out.values())
    found.append(Expectation("shutdown", "", status="pending", seen="the launch was not stopped"))
    return found


def _sim_time_argv(argv: Sequence[str]) -> bool:
    return any(a.lower() in ("use_sim_time:=true", "use_sim_time:=1") for a in argv)


def _involve(expectation: Expectation, specs: list[ProcessSpec]) -> None:
    """Which processes' output explains this expectation; compile an output regex."""
    if expectation.kind in ("node", "lifecycle"):
        expectation.labels = [
            s.label
            for s in specs
            if s.node is not None and s.node.fully_qualified_name == expectation.target
        ]
    elif expectation.kind == "output":
        names = {s.label for s in specs} | {s.base_name for s in specs}
        head, sep, tail = expectation.target.partition(":")
        if sep and head in names:
            expectation.process, expectation.target = head, tail
        if expectation.process:
            expectation.labels = [
                s.label for s in specs if expectation.process in (s.label, s.base_name)
            ]
        try:
            expectation.regex = re.compile(expectation.target)
        except re.error as e:
            raise UsageError(
                f"output expectation ({expectation.origin}): {expectation.target!r} is not a"
                f" regular expression: {e}"
            )


def supervise(
    opts: Any,
    settings: Settings,
    plan: Plan,
    options: Any,
    labels: Any,
    log_dir: str,
    path: str,
    expectations: list[Expectation],
    life: Lifeline,
) -> int:
    """Run the plan as ``mlaunch FILE`` would (the same parts attached), plus the smoke checks.

    The checks attach last, so lifecycle driving, if the plan needs it, already exists and its
    ROS graph is shared.
    """
    from mlaunch.run import pipeline

    runs: list[SmokeRun] = []

    def attach(run: pipeline.Run) -> SmokeRun:
        smoke = SmokeRun(run.supervisor, expectations, settings, lifecycle=run.lifecycle)
        runs.append(smoke)
        return smoke

    parts = [*pipeline.standard_parts(opts), attach]
    code = pipeline.supervise(opts, plan, options, labels, log_dir, life, parts)
    if not runs:
        return code
    smoke = runs[0]
    smoke.conclude()
    report = Report(path, expectations, smoke.rings, smoke.elapsed())
    sys.stdout.write(report.table())
    sys.stdout.flush()
    if settings.junit:
        report.write_junit(settings.junit)
    if code >= 128:
        return code  # interrupted: say so, whatever was seen
    return EXIT_OK if report.passed else EXIT_FAILURE


# --- watching the run -----------------------------------------------------------------------------


class SmokeRun:
    """Attached to the supervisor: decides ready / failed, then shuts the launch down.

    Process and output checks run in the supervisor's loop thread (its event stream);
    ROS graph checks run in one checker thread that hands its findings to the loop.
    """

    def __init__(
        self,
        supervisor: Supervisor,
        expectations: list[Expectation],
        settings: Settings,
        *,
        lifecycle: LifecycleManager | None = None,
    ) -> None:
        from mlaunch.ros.handoff import LoopCall, SharedGraph

        self.supervisor = supervisor
        self.expectations = expectations
        self.settings = settings
        self.phase = "waiting"  # waiting -> holding -> done
        self.failed_reason = ""
        self.rings: dict[str, deque[str]] = {}
        self.loop = LoopCall(supervisor.selector)
        self.started_at = supervisor.clock()
        self._stop = threading.Event()
        graph_env = _graph_environ(supervisor.plan)
        self.graph: SharedGraph = (
            lifecycle.graph
            if lifecycle is not None
            else SharedGraph(graph_env, f"_mlaunch_test_{os.getpid()}")
        )
        self._own_graph = lifecycle is None
        self._checker: threading.Thread | None = None
        supervisor.events.subscribe(self._on_event)
        supervisor.schedule(TICK, self._tick, keeps_alive=False)
        if any(e.kind in GRAPH_KINDS for e in expectations):
            self._checker = threading.Thread(
                target=self._check_graph, name="mlaunch-test-graph", daemon=True
            )
            self._checker.start()

    def elapsed(self) -> float:
        return self.supervisor.clock() - self.started_at

    # --- loop thread ---------------------------------------------------------------------------

    def _on_event(self, event: Event) -> None:
        """The subscription: output, starts and exits, and the lifecycle manager's results."""
        from mlaunch.ros.lifecycle import Outcome

        if isinstance(event, Output):
            self._on_output(event.process.label, event.data)
        elif isinstance(event, Started):
            self._on_process(False, event.process)
        elif isinstance(event, Exited):
            self._on_process(True, event.process)
        elif isinstance(event, Outcome):
            self._on_transition(event)

    def _on_output(self, label: str, data: bytes) -> None:
        lines = _ANSI.sub("", data.decode("utf-8", "replace")).splitlines()
        ring = self.rings.get(label)
        if ring is None:
            ring = self.rings[label] = deque(maxlen=RING_LINES)
        ring.extend(lines)
        if self.phase == "done":
            return
        for e in self.expectations:
            if e.kind != "output" or e.status != "pending" or e.regex is None:
                continue
            if e.process and e.process not in (label, label.rsplit("-", 1)[0]):
                continue
            for line in lines:
                if e.regex.search(line):
                    self._met(e, f"{label}: {line.strip()[:160]}")
                    break
        self._maybe_ready()

    def _on_process(self, exited: bool, process: Process) -> None:
        label = process.label
        e = next((x for x in self.expectations if x.key() == ("process", label)), None)
        if e is None:
            e = Expectation("process", label, origin="started later", labels=[label])
            self.expectations.insert(len(self.expectations) - 1, e)
        if not exited:
            if e.status == "pending":
                self._met(e, f"running (pid {process.pid})")
            return
        self._exited(e, process)

    def _exited(self, e: Expectation, process: Process) -> None:
        from mlaunch.run.process import describe_status

        code = process.returncode if process.returncode is not None else 0
        uptime = max(0.0, process.ended_at - process.started_at)
        what = f"{describe_status(code)} after {uptime:.1f} s (pid {process.pid})"
        if self.phase == "done" or process.stopping or self.supervisor.shutting_down:
            return
        if code == 0 and process.spec.respawn.mode == "never":
            e.seen = f"{what}: a one-shot, finished"
            return
        if code == 0 and _allowed(process.spec, self.settings.allow_exit):
            e.seen = f"{what}: allowed by --allow-exit"
            return
        self._fail(e, f"{what}, before the test ended")

    def _on_transition(self, outcome: Outcome) -> None:
        """The lifecycle manager's results: a failed bring-up fails its node's check at once."""
        result = outcome.result
        if result.ok or outcome.reason not in ("autostart", "sequence", "respawn"):
            return
        for e in self.expectations:
            if e.kind == "lifecycle" and e.target == result.node and e.status != "failed":
                self._fail(e, result.detail)

    def _tick(self) -> None:
        if self.phase == "done":
            return
        now = self.elapsed()
        expired = []
        for e in self.expectations:
            deadline = e.within if e.within is not None else self.settings.timeout
            if e.status == "pending" and e.kind != "shutdown" and now >= deadline:
                expired.append((e, f"{e.seen} (deadline {deadline:g} s passed)"))
        if expired and self.phase == "waiting":
            # Every check past its deadline is reported, not just the first one.
            for e, seen in expired:
                self._mark(e, "failed", seen)
            self._finish(f"mlaunch test failed: {expired[0][0].describe()}: {expired[0][1]}")
        self._maybe_ready()
        if self.phase != "done":
            self.supervisor.schedule(TICK, self._tick, keeps_alive=False)

    def _apply(self, findings: list[tuple[Expectation, bool, str]]) -> None:
        for e, met, seen in findings:
            if e.status != "pending" or self.phase == "done":
                continue
            if met:
                self._met(e, seen)
            else:
                e.seen = seen
        self._maybe_ready()

    def _mark(self, e: Expectation, status: str, seen: str) -> None:
        e.status, e.seen, e.at = status, seen, self.elapsed()

    def _met(self, e: Expectation, seen: str) -> None:
        self._mark(e, "met", seen)

    def _fail(self, e: Expectation, seen: str) -> None:
        if self.phase == "done":
            return
        self._mark(e, "failed", seen)
        self._finish(f"mlaunch test failed: {e.describe()}: {seen}")

    def _fail_all(self, expectations: list[Expectation], seen: str) -> None:
        if self.phase == "done" or not expectations:
            return
        for e in expectations:
            self._mark(e, "failed", seen)
        self._finish(f"mlaunch test failed: {seen}")

    def _maybe_ready(self) -> None:
        if self.phase != "waiting":
            return
        if any(e.status == "pending" and e.kind != "shutdown" for e in self.expectations):
            return
        self.phase = "holding"
        printer = self.supervisor.printer
        count = sum(1 for e in self.expectations if e.status == "met")
        printer.message("INFO", "test", f"ready after {self.elapsed():.1f} s ({count} checks met)")
        if self.settings.hold > 0:
            printer.message("INFO", "test", f"holding for {self.settings.hold:g} s")
            self.supervisor.schedule(self.settings.hold, self._held, keeps_alive=False)
        else:
            self._held()

    def _held(self) -> None:
        self._finish("mlaunch test: ready" + (", held" if self.settings.hold else ""))

    def _finish(self, reason: str) -> None:
        if self.phase == "done":
            return
        wait = self._starting_for()
        if wait > 0:
            # Let the youngest process finish starting (see STARTUP_GRACE); checks still run.
            self.supervisor.schedule(wait, lambda: self._finish(reason), keeps_alive=False)
            return
        self.phase = "done"
        self.failed_reason = reason if "failed" in reason else ""
        self._stop.set()
        self.supervisor.begin_shutdown(reason)

    def _starting_for(self) -> float:
        """How much longer the youngest running process needs to reach STARTUP_GRACE of age."""
        now = self.supervisor.clock()
        ages = [now - p.started_at for p in self.supervisor.processes if p.running]
        return max(0.0, STARTUP_GRACE - min(ages)) if ages else 0.0

    # --- checker thread ---------------------------------------------------------------------------

    def _check_graph(self) -> None:
        from mlaunch.ros.graph_types import GraphNotRunning, RosBridgeError

        try:
            graph = self.graph.get()
        except GraphNotRunning:
            return
        except RosBridgeError as exc:
            # No graph (rclpy missing, a bad ROS_DOMAIN_ID): nothing will change by waiting.
            message = f"cannot look at the ROS graph: {exc}"
            failing = self._graph_expectations()
            self.loop.call_soon(lambda: self._fail_all(failing, message))
            return
        probe = GraphProbe(graph)
        while not self._stop.is_set():
            try:
                findings = probe.check(self._graph_expectations())
            except GraphNotRunning:
                return
            except RosBridgeError as exc:
                findings = [
                    (e, False, f"ROS graph error: {exc}") for e in self._graph_expectations()
                ]
            self.loop.call_soon(lambda f=findings: self._apply(f))  # type: ignore[misc]
            if not self._graph_expectations():
                return
            self._stop.wait(GRAPH_PERIOD)

    def _graph_expectations(self) -> list[Expectation]:
        return [e for e in self.expectations if e.kind in GRAPH_KINDS and e.status == "pending"]

    # --- the end ----------------------------------------------------------------------------------

    def conclude(self) -> None:
        """After the run: pending checks did not happen; the stop ladder check."""
        reason = self.supervisor.shutdown_reason or "it ended"
        stopped_early = any(e.status == "failed" for e in self.expectations)
        for e in self.expectations:
            if e.kind == "shutdown":
                self._conclude_shutdown(e)
            elif e.status == "pending" and stopped_early:
                # Undecided, not failed: the test stopped at the first failure.
                seen = f"undecided, the test stopped at a failure (last seen: {e.seen})"
                self._mark(e, "skipped", seen)
            elif e.status == "pending":
                self._mark(e, "failed", f"{e.seen}; the launch shut down first ({reason})")

    def _conclude_shutdown(self, e: Expectation) -> None:
        records = getattr(self.supervisor, "records", None) or {}
        killed = [r.label for r in records.values() if signal.SIGKILL in r.signals]
        e.labels = killed
        if killed:
            seen = f"needed SIGKILL: {', '.join(killed)} (ignored SIGINT and SIGTERM)"
            self._mark(e, "failed", seen)
        elif any(p.running for p in self.supervisor.processes):
            self._mark(e, "failed", "processes still running when mlaunch ended")
        else:
            self._mark(e, "met", "every process ended after SIGINT or SIGTERM")

    def close(self) -> None:
        self._stop.set()
        self.loop.close()
        if self._checker is not None:
            self._checker.join(timeout=2.0)
        if self._own_graph:
            self.graph.close()


def _messages(count: int) -> str:
    return "1 message" if count == 1 else f"{count} messages"


def _allowed(spec: ProcessSpec, allowed: Iterable[str]) -> bool:
    return any(name in (spec.label, spec.base_name) for name in allowed)


def _graph_environ(plan: Plan) -> dict[str, str]:
    """The environment of the launch's first ROS node (its ROS_DOMAIN_ID), else mlaunch's."""
    for spec in plan.processes():
        if spec.node is not None:
            return dict(spec.env)
    return dict(os.environ)


class GraphProbe:
    """Evaluates graph expectations against one RosGraph (runs in the checker thread)."""

    def __init__(self, graph: Any) -> None:
        self.graph = graph
        self.watches: dict[str, Any] = {}
        self.clock_first: float | None = None

    def check(self, expectations: list[Expectation]) -> list[tuple[Expectation, bool, str]]:
        nodes = self.graph.node_names()
        topics = self.graph.topic_types()
        services = (
            self.graph.service_names() if any(e.kind == "service" for e in expectations) else set()
        )
        out: list[tuple[Expectation, bool, str]] = []
        for e in expectations:
            check: Callable[..., tuple[bool, str]] = getattr(self, f"_{e.kind}")
            met, seen = check(e, nodes=nodes, topics=topics, services=services)
            out.append((e, met, seen))
        return out

    def _node(self, e: Expectation, *, nodes: set[str], **_: Any) -> tuple[bool, str]:
        if e.target in nodes:
            return True, "in the graph"
        visible = sorted(n for n in nodes if not n.rsplit("/", 1)[-1].startswith("_"))
        shown = ", ".join(visible[:8]) + (" ..." if len(visible) > 8 else "")
        return False, f"not in the graph (nodes seen: {shown or 'none'})"

    def _lifecycle(self, e: Expectation, *, nodes: set[str], **_: Any) -> tuple[bool, str]:
        from mlaunch.ros.graph_types import RosTimeout

        if e.target not in nodes:
            return False, "the node is not in the graph"
        try:
            state = self.graph.lifecycle_state(e.target, STATE_QUERY_TIMEOUT)
        except RosTimeout as exc:
            return False, f"no state: {exc}"
        return state == e.state, f"state {state!r}"

    def _service(self, e: Expectation, *, services: set[str], **_: Any) -> tuple[bool, str]:
        if e.target in services:
            return True, "offered"
        return False, f"not offered ({len(services)} services in the graph)"

    def _topic(self, e: Expectation, *, topics: dict[str, list[str]], **_: Any) -> tuple[bool, str]:
        watch = self.watches.get(e.target)
        if watch is None:
            watch = self.watches[e.target] = self.graph.watch_topic(e.target)
        if watch.error:
            return False, watch.error
        if watch.count == 0:
            if e.target not in topics:
                return False, "not in the graph (no publisher or subscriber)"
            types = ", ".join(topics[e.target])
            return False, f"in the graph ({types}) but no message received"
        if e.rate is None:
            return True, f"{_messages(watch.count)} received"
        window = max(2.0, 5.0 / e.rate)
        measured = watch.rate(window)
        wanted = e.rate * RATE_TOLERANCE
        seen = f"{measured:.1f} Hz over the last {window:g} s ({_messages(watch.count)})"
        # A rate from a handful of arrivals is mostly jitter: it passes only from a few more.
        if watch.count < max(3, min(10, int(e.rate))):
            return False, f"still measuring: {seen}, wanted >= {wanted:.1f} Hz"
        if measured >= wanted:
            return True, seen
        return False, f"too slow: {seen}, wanted >= {wanted:.1f} Hz"

    def _clock(self, e: Expectation, **_: Any) -> tuple[bool, str]:
        watch = self.watches.get("/clock")
        if watch is None:
            watch = self.watches["/clock"] = self.graph.clock()
        message = watch.last_message()
        if message is None:
            return False, watch.error or "no /clock message received"
        now = message.clock.sec + message.clock.nanosec * 1e-9
        if self.clock_first is None:
            self.clock_first = now
        if now > self.clock_first:
            return True, f"advanced from {self.clock_first:.2f} s to {now:.2f} s"
        return False, f"stuck at {now:.2f} s ({_messages(watch.count)})"


# --- the report -----------------------------------------------------------------------------------


class Report:
    """The summary table and the JUnit file, from the expectations after the run."""

    def __init__(
        self,
        path: str,
        expectations: list[Expectation],
        rings: dict[str, deque[str]],
        duration: float,
    ) -> None:
        self.path = path
        self.expectations = expectations
        self.rings = rings
        self.duration = duration

    @property
    def failures(self) -> list[Expectation]:
        return [e for e in self.expectations if e.status == "failed"]

    @property
    def passed(self) -> bool:
        return all(e.status == "met" for e in self.expectations)

    def table(self) -> str:
        failed = self.failures
        verdict = "PASSED" if not failed else f"FAILED ({len(failed)} of {len(self.expectations)})"
        out = [
            "",
            f"mlaunch test {verdict} in {self.duration:.1f} s: {self.path}",
        ]
        rows = [
            (STATUS_MARKS.get(e.status, "?"), _at(e), e.describe(), e.seen)
            for e in self.expectations
        ]
        w_expect = min(60, max(len("expected"), *(len(r[2]) for r in rows)))
        out.append(f"  {'':4}  {'at':>6}  {'expected':<{w_expect}}  seen")
        for status, at, expected, seen in rows:
            out.append(f"  {status:<4}  {at:>6}  {expected:<{w_expect}}  {seen}")
        for label in self._labels(failed):
            out.append("")
            out.append(f"last output of {label}:")
            lines = list(self.rings.get(label, ())) or ["(no output)"]
            out.extend(f"  | {line}" for line in lines)
        return "\n".join(out) + "\n"

    def _labels(self, failed: list[Expectation]) -> list[str]:
        labels: list[str] = []
        for e in failed:
            for label in e.labels or list(self.rings):
                if label not in labels:
                    labels.append(label)
        return labels

    def excerpt(self, e: Expectation) -> str:
        parts = []
        for label in e.labels or list(self.rings):
            lines = list(self.rings.get(label, ()))
            if not e.labels:
                lines = lines[-5:]
            parts.append(f"--- last output of {label} ---\n" + "\n".join(lines or ["(no output)"]))
        return "\n".join(parts)

    def write_junit(self, path: str) -> None:
        from mlaunch.smoke import junit

        stem = os.path.basename(self.path).split(".")[0] or "launch"
        cases = []
        for e in self.expectations:
            failure = e.seen if e.status == "failed" else None
            cases.append(
                junit.Case(
                    name=e.describe(),
                    classname=f"mlaunch.test.{stem}",
                    time=e.at or 0.0,
                    failure=failure,
                    skipped=e.seen if e.status in ("skipped", "pending") else None,
                    details=f"expected: {e.describe()}\nseen: {e.seen}\nfrom: {e.origin}",
                    system_out=self.excerpt(e) if failure else "",
                )
            )
        junit.write(
            path, f"mlaunch test {os.path.basename(self.path)}", cases, duration=self.duration
        )


def _at(e: Expectation) -> str:
    return "" if e.at is None else f"{e.at:.1f}s"
