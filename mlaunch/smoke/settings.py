"""``mlaunch test FILE [name:=value ...] [options]``: its options (this text is its --help).

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
that exits with a failure (non-zero status, or a signal) fails the test, whenever it happens:
before ready, during the hold or during the shutdown (there, only the stop signal mlaunch sent
is a clean end: "stopped by SIGINT"); a required process (on_exit=Shutdown()) that crashes
fails it although the launch then shuts down as it should. One that exits 0 is a one-shot (a
spawner, a loader) and fine, unless it was started with respawn: a respawning process that
exits fails even with status 0. ``--allow-exit LABEL[:CODES]`` lets a process (label or base
name) end that way: without CODES with status 0; CODES is a comma-separated list of statuses
and signals (``--allow-exit driver:0,3,SIGSEGV``), or ``any``. At the end, a process that
started less than STARTUP_GRACE seconds ago is given the rest of that time before the stop
signals, so it is not interrupted half-way through its imports. Processes started later by
timers or event handlers are watched from when they start.

What cannot heal ends the wait at once, with its reason: a composable node whose load the
container refused, a lifecycle bring-up that failed, a process that failed, and a check whose
processes all ended for good (their output, their nodes once the graph had a second to show
them). The rest is waited for until its deadline (a topic not published yet). The verdict says
how long the launch was watched after ready (the hold and the start-up grace): a failure later
than that is not seen (JUnit properties ready_after, hold, watched_after_ready).

More expectations, from the command line (each has the overall ``--timeout`` as deadline unless
``--within S`` follows it):
  --expect-topic /scan[:RATE_HZ]     messages arrive (at >= 90% of RATE_HZ, when given)
  --expect-service /map_server/load_map
  --expect-node /robot1/amcl
  --expect-lifecycle /robot1/amcl[:STATE]   (default active; replaces the default check)
  --expect-output 'LABEL:REGEX' | 'REGEX'   a line of output (LABEL: a process label like
                                     talker-1 or its base name talker) matches REGEX
  --expect-clock /clock              simulated time advances (also without use_sim_time)
  --expect-tf odom:base_link         /tf or /tf_static link the two frames
  --expect-param /rsp:publish_frequency=20.0   the node's parameter reads that value
  --expect-action /navigate_to_pose  an action server is offered
  --forbid-output '[LABEL:]REGEX'    no line of output matches REGEX, at any time of the run
  --no-errors                        no process logs an ERROR or FATAL line (off by default)
  --expect 'KIND TARGET [within S]'  the same in one string (KIND: topic, service, node,
                                     lifecycle, output, clock, tf, param, action, forbid)
or from the launch file:
  - any launch configuration whose name starts with ``mlaunch_expect`` holds one expectation
    as 'KIND TARGET [within S]', e.g. in YAML
    ``- let: {name: mlaunch_expect_scan, value: "topic /scan:10 within 15"}``, in XML
    ``<let name="mlaunch_expect_scan" value="topic /scan:10"/>`` (it must be set where the
    top level of the launch sees it: at the top level, or in an included file, not in a group);
  - in Python, ``mlaunch.commands.smoke.Expect(topic="/scan", rate=10.0, within=15)`` (or
    ``service=``, ``node=``, ``lifecycle=`` with ``state=``, ``output=`` or ``forbid=`` with
    ``process=``, ``tf=``, ``param=``, ``action=``).
A normal ``mlaunch FILE`` run ignores both.

Each run gets a ROS domain of its own when ROS_DOMAIN_ID is not set: a free id, claimed with a
lock for as long as the run lasts, and discovery on this machine
(ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST); the verdict names it. ``mlaunch test A B C -j N``
tests several launch files, N at a time, each in a domain of its own, with one report and one
JUnit file holding a testsuite per file.

The evidence of a failed run (``--artifacts DIR`` writes it always): the verdict and the plan
as JSON, each process's argv, environment, parameters and last output, the log files, a
backtrace of a core dump (with gdb), and the last ``--record-seconds`` (10) of the topics the
checks name and ``--record TOPIC`` as an MCAP file; the report says where.

Exit status: 0 ready (and held, and stopped cleanly); 1 an expectation failed; 2 bad command
line or launch file; 128+N interrupted by signal N.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from mlaunch.plan.argparser import ArgumentParser
from mlaunch.plan.errors import UsageError
from mlaunch.smoke.expectations import ERROR_LINES, KINDS, Expectation, parse_spec, parse_target

_HELP = __doc__ or ""
DEFAULT_TIMEOUT = 30.0
# Held after ready so a node that crashes a few seconds in is caught (--hold 0 skips it).
DEFAULT_HOLD = 3.0
HELP = {
    "topic": "/scan[:RATE_HZ]: messages arrive (at >= 90%% of RATE_HZ)",
    "service": "/name: the service is offered",
    "node": "/ns/name: the node is in the ROS graph",
    "lifecycle": "/ns/name[:STATE]: the managed node is in STATE (active)",
    "output": "'LABEL:REGEX' or 'REGEX': a line of output matches",
    "clock": "/clock: simulated time advances (implied by use_sim_time)",
    "tf": "PARENT:CHILD: /tf or /tf_static link the two frames (odom:base_link)",
    "param": "/NODE:NAME=VALUE: the node's parameter reads VALUE (as YAML reads it)",
    "action": "/name: an action server is offered",
}

# --- the command line -----------------------------------------------------------------------------


@dataclass
class Settings:
    """What ``mlaunch test`` adds to ``mlaunch FILE``'s options."""

    expectations: list[Expectation] = field(default_factory=list)
    timeout: float = DEFAULT_TIMEOUT
    hold: float = DEFAULT_HOLD
    junit: str | None = None
    allow_exit: list[str] = field(default_factory=list)
    repeat: int = 1
    json: bool = False  # --format json: the verdict as JSON on stdout
    artifacts: str | None = None  # --artifacts DIR: the evidence, always
    record: list[str] = field(default_factory=list)  # --record TOPIC: kept for the evidence
    record_seconds: float = 10.0
    stdout: int | None = None  # the verdict's stdout, while the run's output goes to stderr


VALUE_FLAGS = (
    "--expect",
    "--expect-topic",
    "--expect-service",
    "--expect-node",
    "--expect-lifecycle",
    "--expect-output",
    "--expect-tf",
    "--expect-param",
    "--expect-action",
    "--forbid-output",
    "--repeat",
    "--artifacts",
    "--record",
    "--record-seconds",
    "--within",
    "--timeout",
    "--hold",
    "--junit",
    "--junit-xml",
    "--allow-exit",
)


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(
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
        if kind == "forbid":
            continue
        group.add_argument(
            f"--expect-{kind}",
            metavar=kind.upper(),
            action=_ExpectAction,
            const=kind,
            help=HELP[kind],
        )
    group.add_argument(
        "--forbid-output",
        metavar="'[LABEL:]REGEX'",
        action=_ExpectAction,
        const="forbid",
        help="fails when a line of output (of LABEL) matches REGEX, at any time of the run",
    )
    group.add_argument(
        "--no-errors",
        action="store_true",
        help="fails when any process logs an ERROR or FATAL line (off by default)",
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
    parser.add_argument(
        "--junit",
        "--junit-xml",  # launch_testing's name for it: both work for either kind of file
        metavar="FILE",
        dest="junit",
        help="write a JUnit XML report",
    )
    parser.add_argument(
        "--artifacts",
        metavar="DIR",
        help="write the evidence of the run into DIR (verdict, plan, processes, logs, the"
        " recording); without it, a failed run writes it into its log folder",
    )
    parser.add_argument(
        "--record",
        action="append",
        default=[],
        metavar="TOPIC",
        help="keep the last seconds of TOPIC for the evidence (besides the topics the checks"
        " name); repeatable",
    )
    parser.add_argument(
        "--record-seconds",
        type=float,
        default=10.0,
        metavar="S",
        help="how many of the last seconds the recording keeps (default 10; 0: no recording)",
    )
    parser.add_argument(
        "--repeat",
        type=int,
        default=1,
        metavar="N",
        help="run the test N times and say, per check, how often it held (flakiness)",
    )
    parser.add_argument(
        "-j",
        "--jobs",
        metavar="N",
        help="test several launch files (mlaunch test A B C -j N), N at a time, each in a ROS"
        " domain of its own; one report, one JUnit file",
    )
    parser.add_argument(
        "--allow-exit",
        action="append",
        default=[],
        metavar="LABEL[:CODES]",
        help="a process (label or base name) that may end with status 0, or with one of CODES"
        " (statuses and signals, comma-separated: driver:3,SIGSEGV; or driver:any); repeatable."
        " A process without respawn that exits 0 is a one-shot, fine anyway",
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
        elif arg in ("-h", "--help", "--no-errors"):
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
    for value in ns.allow_exit:
        parse_allow_exit(value)  # a bad CODES is a usage error before anything starts
    if ns.repeat < 1:
        raise UsageError(f"--repeat {ns.repeat!r}: expected a number of runs >= 1")
    expectations = list(getattr(ns, "expectations", None) or [])
    if ns.no_errors:
        expectations.append(parse_target("forbid", ERROR_LINES, "--no-errors"))
    if not ns.record_seconds >= 0 or ns.record_seconds == float("inf"):
        raise UsageError(f"--record-seconds {ns.record_seconds!r}: expected seconds >= 0")
    return Settings(
        artifacts=ns.artifacts,
        record=[topic if topic.startswith("/") else f"/{topic}" for topic in ns.record],
        record_seconds=ns.record_seconds,
        repeat=ns.repeat,
        expectations=expectations,
        timeout=ns.timeout,
        hold=ns.hold,
        junit=ns.junit,
        allow_exit=list(ns.allow_exit),
    )


def parse_allow_exit(value: str) -> tuple[str, frozenset[int] | None]:
    """``LABEL[:CODES]`` of --allow-exit: (label, the return codes allowed; None: any).

    Return codes as the supervisor has them: a status (0-255) or minus a signal's number.
    """
    import signal

    label, sep, codes = value.partition(":")
    if not label:
        raise UsageError(f"--allow-exit {value!r}: expected LABEL[:CODES] (a process label first)")
    if not sep:
        return label, frozenset({0})
    if codes.strip().lower() == "any":
        return label, None
    allowed: set[int] = set()
    for word in codes.split(","):
        word = word.strip()
        name = word.upper() if word.upper().startswith("SIG") else "SIG" + word.upper()
        if word.isdigit() and int(word) <= 255:
            allowed.add(int(word))
        elif name in signal.Signals.__members__:
            allowed.add(-signal.Signals[name].value)
        else:
            raise UsageError(
                f"--allow-exit {value!r}: {word!r} is neither an exit status (0-255) nor a signal"
                " name (SIGSEGV, ABRT ...); CODES is a comma-separated list of them, or 'any'"
            )
    return label, frozenset(allowed)
