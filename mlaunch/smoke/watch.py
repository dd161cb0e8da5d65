"""Watching a smoke run: ready or failed, from the supervisor's events and the ROS graph."""

from __future__ import annotations

import functools
import os
import re
import signal
import threading
from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from mlaunch.engine.part import Part
from mlaunch.plan.records import Exited, HandedOff, LoadRefused, Output, Record, Said, Started
from mlaunch.smoke.expectations import Expectation
from mlaunch.smoke.settings import Settings

if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Protocol

    from mlaunch.engine.part import AttachedRun, EndingRun
    from mlaunch.engine.process import Process
    from mlaunch.engine.process_state import ProcessState
    from mlaunch.plan.steps import Plan

    class CheckedRun(AttachedRun, EndingRun, Protocol):
        """What the smoke checks use of the run (the Supervisor is one): the plan, what it knows
        of each label, its processes, and why it is shutting down."""

        @property
        def plan(self) -> Plan: ...

        @property
        def process_states(self) -> Mapping[str, ProcessState]: ...

        @property
        def processes(self) -> list[Process]: ...

        @property
        def shutdown_reason(self) -> str: ...

    from mlaunch.parts.handoff import SharedGraph
    from mlaunch.parts.lifecycle import LifecycleManager, Outcome
    from mlaunch.parts.ros1_graph import SharedMaster
    from mlaunch.plan.records import ProcessView
    from mlaunch.plan.steps import ProcessSpec
    from mlaunch.smoke.recorder import Recorder
    from mlaunch.smoke.report import Window

# At the end, the youngest process is given up to this long since its start before the stop
# signals: SIGINT during a Python node's imports leaves a traceback in a passing run.
STARTUP_GRACE = 2.0
RING_LINES = 20
# A topic given with a rate passes at this fraction of it (publishers jitter, CI machines lag).
RATE_TOLERANCE = 0.9
# ... and is measured over at least this long (a 30 Hz topic passed on 0.3 s of messages).
MIN_RATE_SPAN = 1.0
# The graph is looked at this often; deadlines are checked this often.
GRAPH_PERIOD = 0.2
TICK = 0.1
# Waiting for a lifecycle node's get_state answer while checking (it is asked again later).
STATE_QUERY_TIMEOUT = 1.0
# A node whose processes all ended for good cannot appear any more; the graph is given this
# long after the last one ended to report what it saw of the node while it ran.
ENDED_GRACE = 1.0
# Where the run was when a process ended, in the words of the report's table.
_PHASES = {
    "waiting": "before the launch was ready",
    "holding": "during the hold",
    "done": "in the shutdown",
}
# The name of a test run's own graph node (its pid follows): another one in the graph means
# another test shares the ROS domain.
TEST_NODE = "_mlaunch_test_"
GRAPH_KINDS = frozenset({"topic", "service", "node", "lifecycle", "clock", "tf", "param", "action"})
_ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")

# --- watching the run -----------------------------------------------------------------------------


class SmokeRun(Part):
    """Attached to the supervisor: decides ready / failed, then shuts the launch down.

    Process and output checks run in the supervisor's loop thread (its record stream);
    ROS graph checks run in one checker thread that hands its findings to the loop.
    """

    # Whose lines the printer shows ([test]; a running launch's readiness says [ready]).
    SOURCE = "test"

    def __init__(
        self,
        supervisor: CheckedRun,
        expectations: list[Expectation],
        settings: Settings,
        *,
        lifecycle: LifecycleManager | None = None,
        graph: SharedMaster | None = None,
        recorder: Recorder | None = None,
    ) -> None:
        from mlaunch.parts.handoff import LoopCall, SharedGraph

        self.supervisor = supervisor
        self.expectations = expectations
        self.settings = settings
        self.phase = "waiting"  # waiting -> holding -> done
        self.failed_reason = ""
        self.rings: dict[str, deque[str]] = {}
        self._ended: set[str] = set()  # labels of processes that ended and are not respawned
        self.ready_at: float | None = None  # seconds from the start; None: never ready
        # Other mlaunch test runs' graph nodes seen in this run's graph: a shared domain.
        self.others: set[str] = set()
        self.ended_at: float | None = None  # when the watch ended (the shutdown was asked)
        self.loop = LoopCall(supervisor.selector)
        self.started_at = supervisor.clock()
        self._stop = threading.Event()
        # ``graph``: a native ROS 1 run's master, checked instead of the ROS 2 graph.
        self.graph: SharedGraph | SharedMaster
        if graph is not None:
            self.graph = graph
        elif lifecycle is not None:
            self.graph = lifecycle.graph
        else:
            graph_env = _graph_environ(supervisor.plan)
            self.graph = SharedGraph(graph_env, f"{TEST_NODE}{os.getpid()}")
        self._own_graph = lifecycle is None or graph is not None
        self._checker: threading.Thread | None = None
        # The last seconds of the named topics, for the evidence of a failure: fed by the graph.
        self.recorder = recorder if graph is None else None
        self._recording = False
        supervisor.records.subscribe(self._on_record)
        supervisor.schedule(TICK, self._tick, keeps_alive=False)
        if any(e.kind in GRAPH_KINDS for e in expectations) or self.recorder is not None:
            self._start_checker()

    def elapsed(self) -> float:
        return self.supervisor.clock() - self.started_at

    # --- loop thread ---------------------------------------------------------------------------

    def _on_record(self, record: Record) -> None:
        """The subscription: output, starts and exits, and the lifecycle manager's results."""
        from mlaunch.parts.lifecycle import Outcome

        if isinstance(record, Output):
            self._on_output(record.process.label, record.data)
        elif isinstance(record, Started):
            self._on_process(False, record.process)
        elif isinstance(record, Exited):
            self._on_process(True, record.process)
        elif isinstance(record, Outcome):
            self._on_transition(record)
        elif isinstance(record, HandedOff):
            self._on_handoff(record.step)
        elif isinstance(record, LoadRefused):
            self._on_refused(record)

    def _on_output(self, label: str, data: bytes) -> None:
        lines = _ANSI.sub("", data.decode("utf-8", "replace")).splitlines()
        ring = self.rings.get(label)
        if ring is None:
            ring = self.rings[label] = deque(maxlen=RING_LINES)
        ring.extend(lines)
        self._forbidden(label, lines)
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

    def _forbidden(self, label: str, lines: list[str]) -> None:
        """--forbid-output, --no-errors: a matching line fails the test whenever it comes (in
        the shutdown too: an error logged while stopping is an error)."""
        for e in self.expectations:
            if e.kind != "forbid" or e.status == "failed" or e.regex is None:
                continue
            if e.process and e.process not in (label, label.rsplit("-", 1)[0]):
                continue
            line = next((x for x in lines if e.regex.search(x)), None)
            if line is None:
                continue
            seen = f"{label}: {line.strip()[:160]}"
            if e.labels == []:
                e.labels = [label]
            if self.phase == "done":
                self._mark(e, "failed", seen)
            else:
                self._fail(e, seen)

    def _on_process(self, exited: bool, process: ProcessView) -> None:
        label = process.label
        e = next((x for x in self.expectations if x.key() == ("process", label)), None)
        if e is None:
            e = Expectation("process", label, origin="started later", labels=[label])
            self.expectations.insert(len(self.expectations) - 1, e)
        if not exited:
            self._ended.discard(label)
            _name_label(self.expectations, process)
            if e.status == "pending":
                self._met(e, f"running (pid {process.pid})")
            return
        self._exited(e, process)
        if process.spec.respawn.mode == "never" or process.user_stop:
            self._ended.add(label)
            self._cannot_appear(process)

    def _cannot_appear(self, process: ProcessView) -> None:
        """Fail what only processes that ended for good could have shown: their output at
        once, their nodes once the graph had ENDED_GRACE to say it saw them."""
        from mlaunch.engine.process import describe_status

        if self.phase != "waiting":
            return
        code = process.returncode if process.returncode is not None else 0
        why = f"{process.label} ended ({describe_status(code)}) and is not started again"
        for e in self.expectations:
            if e.status != "pending" or not e.labels or not set(e.labels) <= self._ended:
                continue
            if e.kind == "output" and e.process:
                self._fail(e, f"no line matched before {why}")
            elif e.kind in ("node", "lifecycle"):
                self.supervisor.schedule(
                    ENDED_GRACE, functools.partial(self._gone, e, why), keeps_alive=False
                )

    def _gone(self, e: Expectation, why: str) -> None:
        if e.status == "pending" and set(e.labels) <= self._ended:
            self._fail(e, f"{e.seen}; it cannot appear: {why}")

    def _on_refused(self, event: LoadRefused) -> None:
        """A container refused a load: that node cannot appear, whatever the deadline (a
        refusal that comes as the launch stops still counts: it is an answer, not a race)."""
        e = next((x for x in self.expectations if x.key() == ("node", event.node)), None)
        if e is None:
            labels = [
                p.label
                for p in self.supervisor.processes
                if p.spec.node is not None and p.spec.node.fully_qualified_name == event.container
            ]
            e = Expectation("node", event.node, origin="loaded later", labels=labels)
            self.expectations.insert(len(self.expectations) - 1, e)  # before 'shutdown'
        reason = event.reason or "no reason given"
        seen = f"container {event.container} refused to load {event.plugin}: {reason}"
        if self.phase == "done":
            self._mark(e, "failed", seen)
        else:
            self._fail(e, seen)

    def _on_handoff(self, step: object) -> None:
        """Components loaded later (a timer's or a handler's loads) are nodes the graph must
        show, as the plan's are; the plan's own are expected already."""
        from mlaunch.launch_ros.composition import LoadComponents

        if not isinstance(step, LoadComponents) or self.phase == "done":
            return
        keys = {e.key() for e in self.expectations}
        target = step.target
        labels = [
            p.label
            for p in self.supervisor.processes
            if p.spec.node is not None and p.spec.node.fully_qualified_name == target
        ]
        added = False
        for name in step.component_names():
            if ("node", name) not in keys:
                e = Expectation("node", name, origin="loaded later", labels=labels)
                self.expectations.insert(len(self.expectations) - 1, e)  # before 'shutdown'
                added = True
        if added and (self._checker is None or not self._checker.is_alive()):
            self._start_checker()

    def _checker_ended(self, thread: threading.Thread) -> None:
        """The checker found nothing left to check; start it again if something came since
        (and no newer checker took over)."""
        if self._checker is thread and self._graph_expectations() and not self._stop.is_set():
            self._start_checker()

    def _start_checker(self) -> None:
        self._checker = threading.Thread(
            target=self._check_graph, name="mlaunch-test-graph", daemon=True
        )
        self._checker.start()

    def _exited(self, e: Expectation, process: ProcessView) -> None:
        """A process ended: a failure whenever it happens (before ready, in the hold, in the
        shutdown), unless it was a one-shot, the end of mlaunch's own stop or allowed."""
        from mlaunch.engine.process import describe_status

        if process.user_stop:
            return  # stopped or restarted through mlaunch ctl: the user's own act
        code = process.returncode if process.returncode is not None else 0
        uptime = max(0.0, process.ended_at - process.started_at)
        what = f"{describe_status(code)} after {uptime:.1f} s (pid {process.pid})"
        if process.stopping:
            if code == 0 or _stop_signal(code, process.signals_sent):
                return  # the stop ladder's own end (SIGKILL: the shutdown check says so)
            what += f", after mlaunch's {'/'.join(_names(process.signals_sent))}"
        elif code == 0 and (process.spec.respawn.mode == "never" or self.supervisor.shutting_down):
            e.seen = f"{what}: a one-shot, finished"
            return
        if _allowed(process.spec, self.settings.allow_exit, code):
            e.seen = f"{what}: allowed by --allow-exit"
            return
        seen = f"{what}, {_PHASES[self.phase]}"
        if self.phase == "done":
            self._mark(e, "failed", seen)  # the verdict counts it; the shutdown is under way
        else:
            self._fail(e, seen)

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
        if any(e.status == "failed" for e in self.expectations):
            return  # stopping at a failure (the youngest process may still finish starting)
        self.phase = "holding"
        self.ready_at = self.elapsed()
        emit = self.supervisor.records.emit
        count = sum(1 for e in self.expectations if e.status == "met")
        emit(Said("INFO", self.SOURCE, f"ready after {self.elapsed():.1f} s ({count} checks met)"))
        if self.settings.hold > 0:
            emit(Said("INFO", self.SOURCE, f"holding for {self.settings.hold:g} s"))
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
        self.ended_at = self.elapsed()
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
        from mlaunch.parts.graph_types import GraphNotRunning, RosBridgeError

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
        if self.recorder is not None and not self._recording:
            self._recording = True
            try:
                self.recorder.attach(graph)
            except RosBridgeError:
                pass  # the checks say what is wrong with the graph; the evidence lacks a recording
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
            if probe.others - self.others:
                others = set(probe.others)
                self.loop.call_soon(lambda o=others: self.others.update(o))  # type: ignore[misc]
            if not self._graph_expectations():
                # A component loaded later may add one as this thread ends: the loop looks.
                me = threading.current_thread()
                self.loop.call_soon(lambda me=me: self._checker_ended(me))  # type: ignore[misc]
                return
            self._stop.wait(GRAPH_PERIOD)

    def _graph_expectations(self) -> list[Expectation]:
        return [e for e in self.expectations if e.kind in GRAPH_KINDS and e.status == "pending"]

    # --- the end ----------------------------------------------------------------------------------

    def window(self) -> Window:
        """How long the run was watched, and how long of that after ready."""
        from mlaunch.smoke.report import Window

        end = self.ended_at if self.ended_at is not None else self.elapsed()
        return Window(self.ready_at, self.settings.hold, end)

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
        records = self.supervisor.process_states
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


def _name_label(expectations: list[Expectation], process: ProcessView) -> None:
    """A node started later (a native ROS 1 run's) was expected under its process's name:
    its output is the started process's, under its label."""
    base = process.spec.base_name
    for e in expectations:
        if e.kind == "node" and base in e.labels and process.label not in e.labels:
            e.labels = [process.label if x == base else x for x in e.labels]
            return


def _messages(count: int) -> str:
    return "1 message" if count == 1 else f"{count} messages"


def _allowed(spec: ProcessSpec, allowed: Iterable[str], code: int) -> bool:
    """Whether an --allow-exit LABEL[:CODES] lets ``spec``'s process end with ``code``."""
    from mlaunch.smoke.settings import parse_allow_exit

    for value in allowed:
        name, codes = parse_allow_exit(value)
        if name in (spec.label, spec.base_name) and (codes is None or code in codes):
            return True
    return False


def _stop_signal(code: int, sent: Iterable[int]) -> bool:
    """Ended by a stop signal mlaunch sent (killed by it, or a shell's 128+N for it)."""
    return any(code in (-sig, 128 + sig) for sig in sent)


def _names(signals: Iterable[int]) -> list[str]:
    from mlaunch.engine.process import signal_name

    return [signal_name(int(s)) for s in signals] or ["stop"]


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
        self.tf: TfLinks | None = None
        self.others: set[str] = set()  # other mlaunch test runs' graph nodes

    def check(self, expectations: list[Expectation]) -> list[tuple[Expectation, bool, str]]:
        nodes = self.graph.node_names()
        mine = f"{TEST_NODE}{os.getpid()}"
        self.others.update(n for n in nodes if n.startswith(f"/{TEST_NODE}") and n[1:] != mine)
        topics = self.graph.topic_types()
        wants = {e.kind for e in expectations}
        services = self.graph.service_names() if wants & {"service", "action"} else set()
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
        from mlaunch.parts.graph_types import RosTimeout

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
                from mlaunch.plan.errors import did_you_mean

                hint = did_you_mean(e.target, topics)
                return False, f"not in the graph (no publisher or subscriber){hint}"
            types = ", ".join(topics[e.target])
            return False, f"in the graph ({types}) but no message received"
        if e.rate is None:
            return True, f"{_messages(watch.count)} received"
        window = max(2.0, 5.0 / e.rate)
        measured = watch.rate(window)
        count, span = watch.recent(window)
        wanted = e.rate * RATE_TOLERANCE
        seen = f"{measured:.1f} Hz over {span:.1f} s ({_messages(count)})"
        # A rate from a handful of arrivals, or from a fraction of a second, is mostly jitter:
        # it is judged only once enough of both came.
        need_count = max(3, min(10, int(e.rate)))
        need_span = max(MIN_RATE_SPAN, (need_count - 1) / e.rate)
        total = (watch.last_at or 0.0) - (watch.first_at or 0.0)
        if watch.count < need_count or total < need_span:
            return False, (
                f"too little data: {_messages(watch.count)} over {total:.1f} s; a rate needs"
                f" {need_count} over {need_span:g} s or more (wanted >= {wanted:.1f} Hz)"
            )
        if measured >= wanted:
            return True, seen
        return False, f"too slow: {seen}, wanted >= {wanted:.1f} Hz"

    def _action(self, e: Expectation, *, services: set[str], **_: Any) -> tuple[bool, str]:
        # An action server offers <name>/_action/send_goal (and its other services).
        if f"{e.target}/_action/send_goal" in services:
            return True, "offered"
        actions = sorted(
            n[: -len("/_action/send_goal")] for n in services if n.endswith("/_action/send_goal")
        )
        from mlaunch.plan.errors import did_you_mean

        return False, f"not offered ({len(actions)} action servers in the graph)" + did_you_mean(
            e.target, actions
        )

    def _param(self, e: Expectation, *, nodes: set[str], **_: Any) -> tuple[bool, str]:
        import yaml

        from mlaunch.parts.graph_types import RosTimeout

        node, _sep, name = e.target.rpartition(":")
        if node not in nodes:
            return False, f"node {node} is not in the graph"
        try:
            found, value = self.graph.parameter(node, name, STATE_QUERY_TIMEOUT)
        except RosTimeout as exc:
            return False, f"no answer: {exc}"
        if not found:
            return False, f"{node} has no parameter {name!r} set"
        try:
            wanted = yaml.safe_load(e.value or "")
        except yaml.YAMLError:
            wanted = e.value
        same = value == wanted or str(value) == str(e.value)
        return same, f"{name} = {value!r}"

    def _tf(self, e: Expectation, **_: Any) -> tuple[bool, str]:
        if self.tf is None:
            self.tf = TfLinks(self.graph)
        parent, _sep, child = e.target.partition(":")
        if self.tf.linked(parent, child):
            return True, f"{parent} -> {child} through {' -> '.join(self.tf.path(parent, child))}"
        frames = sorted(self.tf.frames())
        shown = ", ".join(frames[:10]) + (" ..." if len(frames) > 10 else "")
        return False, self.tf.error or f"not linked (frames seen: {shown or 'none'})"

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


class TfLinks:
    """The frames /tf and /tf_static link (parent -> child), from the graph's messages."""

    TYPE = "tf2_msgs/msg/TFMessage"

    def __init__(self, graph: Any) -> None:
        self.edges: dict[str, set[str]] = {}
        self.lock = threading.Lock()
        self.error = ""
        for topic in ("/tf", "/tf_static"):
            watch = graph.watch_topic(topic, self.TYPE)
            watch.listen(functools.partial(self._message, watch))
            self.error = self.error or (watch.error or "")

    def _message(self, watch: Any) -> None:
        message = watch.last_message()
        if message is None:
            return
        with self.lock:
            for transform in message.transforms:
                parent = transform.header.frame_id.lstrip("/")
                child = transform.child_frame_id.lstrip("/")
                self.edges.setdefault(parent, set()).add(child)
                self.edges.setdefault(child, set()).add(parent)

    def frames(self) -> set[str]:
        with self.lock:
            return set(self.edges)

    def path(self, start: str, end: str) -> list[str]:
        """The frames from ``start`` to ``end`` through the tree (either way), or []."""
        with self.lock:
            edges = {k: set(v) for k, v in self.edges.items()}
        came: dict[str, str] = {start: start}
        todo = [start]
        while todo:
            frame = todo.pop(0)
            if frame == end:
                out = [end]
                while out[-1] != start:
                    out.append(came[out[-1]])
                return out[::-1]
            for near in edges.get(frame, ()):
                if near not in came:
                    came[near] = frame
                    todo.append(near)
        return []

    def linked(self, start: str, end: str) -> bool:
        return bool(self.path(start, end))
