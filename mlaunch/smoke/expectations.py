"""What ``mlaunch test`` checks: expectations, parsed from the command line or the launch file.

``Expect`` (Python) and ``mlaunch_expect*`` launch configurations (any format) put them in the
plan; ``build_expectations`` (mlaunch.commands.smoke) merges them with the defaults.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import perform
from mlaunch.plan.errors import LaunchFileError, UsageError
from mlaunch.plan.steps import Note

if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext

CONFIG_PREFIX = "mlaunch_expect"
KINDS = (
    "topic",
    "service",
    "node",
    "lifecycle",
    "output",
    "clock",
    "tf",
    "param",
    "action",
    "forbid",
)
# --no-errors: a forbidden output of ROS log lines at ERROR or FATAL level.
ERROR_LINES = r"\[(ERROR|FATAL)\]"
LIFECYCLE_STATES = ("unconfigured", "inactive", "active", "finalized")
_WITHIN = re.compile(r"^(?P<body>.*?)\s+within\s+(?P<seconds>[0-9]+(?:\.[0-9]*)?)\s*s?$")

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
    value: str | None = None  # param: the value expected, as YAML reads it
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
        if self.kind == "tf":
            parent, _, child = self.target.partition(":")
            return f"TF links frame {parent} to {child}"
        if self.kind == "param":
            node, _, name = self.target.rpartition(":")
            return f"parameter {name} of {node} is {self.value}"
        if self.kind == "action":
            return f"action server {self.target} is offered"
        if self.kind == "forbid":
            if self.target == ERROR_LINES:
                return "no ERROR or FATAL line in any output"
            where = f"{self.process} " if self.process else "any process "
            return f"no line of {where}matches /{self.target}/"
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
    if kind == "tf":
        parent, sep, child = target.partition(":")
        parent, child = parent.strip().lstrip("/"), child.strip().lstrip("/")
        if not sep or not parent or not child or any(c.isspace() for c in parent + child):
            raise UsageError(
                f"tf expectation {target!r} ({origin}) is not PARENT:CHILD (two frame names,"
                " e.g. odom:base_link)"
            )
        return Expectation("tf", f"{parent}:{child}", origin)
    if kind == "param":
        return _param(target, origin)
    if kind == "action":
        return Expectation("action", _absolute(target, "action", origin), origin)
    if kind == "forbid":
        return Expectation("forbid", target, origin, status="met", seen="no line matched")
    raise UsageError(f"unknown expectation kind {kind!r}; valid: {', '.join(KINDS)}")


def _param(target: str, origin: str) -> Expectation:
    """``/node:name=value``: the node's parameter ``name`` reads ``value`` (as YAML)."""
    head, sep, value = target.partition("=")
    node, colon, name = head.rpartition(":")
    if not sep or not colon or not name.strip() or not node.strip():
        raise UsageError(
            f"param expectation {target!r} ({origin}) is not /NODE:NAME=VALUE"
            " (e.g. /robot_state_publisher:publish_frequency=20.0)"
        )
    full = f"{_absolute(node, 'node', origin)}:{name.strip()}"
    return Expectation("param", full, origin, value=value.strip())


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

    def describe_data(self) -> dict[str, Any]:
        """--print --format json: what ``mlaunch test`` will check (``check`` is its kind)."""
        if self.expectation is None:
            return {"kind": "expectation", "check": None, "target": None, "description": None}
        data = expectation_data(self.expectation)
        del data["source"]  # the step's origin says where it was written
        return {"kind": "expectation", **data}


def expectation_data(e: Expectation) -> dict[str, Any]:
    """--print --format json: one expectation as data (``check`` is its kind, ``source`` where
    it comes from: default, a command-line option, a launch configuration, file:line)."""
    return {
        "check": e.kind,
        "target": e.target,
        "description": e.describe(),
        "within": e.within,
        "rate": e.rate,
        "state": e.state if e.kind == "lifecycle" else None,
        "process": e.process,
        "value": e.value,
        "regex": None if e.regex is None else e.regex.pattern,
        "source": e.origin,
    }


class Expect(Action):
    """An expectation for ``mlaunch test``, written in a Python launch file.

    Exactly one of ``topic`` (with ``rate`` in Hz), ``service``, ``node``, ``lifecycle`` (with
    ``state``, default active), ``output`` or ``forbid`` (a regex, with ``process``: a label or
    base name), ``tf`` ('PARENT:CHILD'), ``param`` ('/NODE:NAME=VALUE') or ``action`` is given;
    ``within`` overrides the run's ``--timeout`` for it.
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
        tf: Any = None,
        param: Any = None,
        action: Any = None,
        forbid: Any = None,
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
                ("tf", tf),
                ("param", param),
                ("action", action),
                ("forbid", forbid),
            )
            if v is not None
        }
        if len(given) != 1:
            raise LaunchFileError(
                "Expect takes exactly one of topic=, service=, node=, lifecycle=, output=, tf=,"
                " param=, action=, forbid="
                f" (got {', '.join(given) or 'none'})",
                where=self.origin,
            )
        ((self.kind, self.target),) = given.items()
        self.rate, self.state, self.process, self.within = rate, state, process, within

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        target = perform(context, self.target)
        where = f"Expect at {self.origin}"
        if self.kind == "topic" and self.rate is not None:
            target = f"{target}:{self.rate}"
        elif self.kind == "lifecycle":
            target = f"{target}:{self.state}"
        elif self.kind in ("output", "forbid") and self.process is not None:
            target = f"{perform(context, self.process)}:{target}"
        try:
            expectation = parse_target(self.kind, target, where)
        except UsageError as e:
            raise LaunchFileError(str(e), where=self.origin) from None
        expectation.within = self.within
        planner.add(ExpectStep(origin=self.origin, expectation=expectation))


class _CollectConfigurations(Action):
    """Appended after the launch file by ``mlaunch test``: reads mlaunch_expect* and sim time."""

    def __init__(self) -> None:
        super().__init__()
        self.found: list[Expectation] = []
        self.use_sim_time = False

    def execute(self, context: LaunchContext) -> None:
        configs = context.launch_configurations
        for name in sorted(configs):
            if name.startswith(CONFIG_PREFIX):
                origin = f"launch configuration {name}"
                self.found.append(parse_spec(str(configs[name]), origin))
        for entry in configs.get("global_params", ()) or ():
            if isinstance(entry, tuple) and entry[0] == "use_sim_time":
                self.use_sim_time = _true(entry[1])


def _true(value: Any) -> bool:
    return value is True or str(value).strip().lower() in ("true", "1", "yes", "on")
