"""Managed (lifecycle) nodes in a running launch: bring-up, launch_ros's events, ordered sequences.

What it does, attached to the supervisor by the pipeline when the plan needs it (Plan.needs):

- ``LifecycleNode(..., autostart=True)`` (``lifecycle_node autostart="true"`` in YAML/XML) is
  driven to ``active`` once its process starts: its ``get_state``/``change_state`` services are
  awaited with a deadline, then ``configure`` and ``activate`` are asked for, starting from
  whatever state it is in. A respawned node is driven back to ``active`` the same way.
- A ``ComposableLifecycleNode(..., autostart=True)`` (``composable_lifecycle_node``) is driven
  the same way once its container answered that it loaded it (``ComponentLoaded``), and again
  each time it is loaded anew (``mlaunch ctl load``). It lives as long as its container's
  process; a failed transition is said and ends nothing (it has no ``required``).
- ``EmitEvent(event=ChangeState(lifecycle_node_matcher=..., transition_id=...))`` asks the matched
  running lifecycle nodes for that transition; ``OnStateTransition`` handlers fire on the
  ``<node>/transition_event`` messages, as in launch_ros.
- ``LifecycleSequence(nodes=[...])`` brings nodes up in order, each waiting for the previous one
  to be active (nav2's lifecycle manager, declared in the launch). In YAML/XML, declare the launch
  argument ``mlaunch_lifecycle_sequence`` with a literal default listing the nodes (spaces or
  commas between them), e.g. ``<arg name="mlaunch_lifecycle_sequence" default="/map /amcl"/>``
  (``mlaunch_lifecycle_sequence:=...`` on the command line overrides it). The nodes of a sequence
  are driven only by it (their ``autostart`` is ignored).
- On shutdown, active nodes are deactivated in the reverse order of their activation before
  their processes get the stop signals (bounded: DEACTIVATE_TIMEOUT per node).
- A failed transition is printed with the node, the transition and the node's answer. It shuts
  the launch down with exit status 1 when the launch chose so: ``required=True`` on the node, or
  ``shutdown_on_failure=True`` (the default) on a sequence.

ROS work goes through ``mlaunch.parts.bridge`` only, from worker threads; results come back to the
supervisor's loop thread through ``LoopCall`` (a queue and a wakeup pipe in its selector).
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mlaunch.engine.part import Part
from mlaunch.launch_ros.lifecycle_sequence import (
    DEFAULT_TIMEOUT,
    LifecycleSequence,
    SequenceStep,
    sequence_from_arguments,
)
from mlaunch.parts.handoff import LoopCall, SharedGraph
from mlaunch.plan.errors import EXIT_FAILURE
from mlaunch.plan.records import (
    ComponentLoaded,
    Exited,
    LaunchEvent,
    Record,
    Said,
    ShutdownBegun,
    Started,
    Transition,
)
from mlaunch.plan.steps import ProcessSpec

if TYPE_CHECKING:
    from typing import Protocol

    from mlaunch.engine.part import AttachedRun, EndingRun
    from mlaunch.engine.process import Process
    from mlaunch.plan.steps import Plan

    class DrivenRun(AttachedRun, EndingRun, Protocol):
        """What lifecycle driving uses of the run (the Supervisor is one): the plan (its
        lifecycle nodes, their environment), its processes, and a process's stop held back
        while its node deactivates."""

        @property
        def plan(self) -> Plan: ...

        @property
        def processes(self) -> list[Process]: ...

        def hold_stop(self, process: Process) -> None: ...

        def release_stop(self, process: Process) -> None: ...

    from mlaunch.parts.bridge import RosGraph, TransitionResult
    from mlaunch.plan.records import ProcessView

# get_state is asked again this often while waiting for a node (a lost request is not fatal).
STATE_ATTEMPT = 2.0
# At shutdown each active node gets this long to deactivate before its stop ladder starts.
DEACTIVATE_TIMEOUT = 3.0
SOURCE = "lifecycle"
# What a node needs, from each state, to become active.
TO_ACTIVE: dict[str, tuple[str, ...]] = {
    "unconfigured": ("configure", "activate"),
    "inactive": ("activate",),
    "active": (),
}
# ChangeState transition ids (lifecycle_msgs/msg/Transition) -> the bridge's transition labels.
TRANSITION_LABELS: dict[int, str] = {
    1: "configure",
    2: "cleanup",
    3: "activate",
    4: "deactivate",
    5: "shutdown",
    6: "shutdown",
    7: "shutdown",
}


# --- the running side ---------------------------------------------------------------------------


@dataclass
class Managed:
    """One lifecycle node of the launch, as the manager knows it."""

    fqn: str
    spec: ProcessSpec
    drive: str = ""  # "autostart", "sequence" or "" (only events move it)
    process: ProcessView | None = None
    generation: int = 0  # bumped on every exit, so a late result of a dead process is ignored
    state: str = "unknown"
    brought_up: bool = False
    subscribed: bool = False
    # A composable node's: what ChangeState matchers and StateTransition events see (its
    # spec is its container's).
    component: ComponentTarget | None = None

    @property
    def required(self) -> bool:
        return self.spec.required and self.component is None

    @property
    def action(self) -> Any:
        """What launch_ros's events name as the node: its action, or the component."""
        return self.component if self.component is not None else self.spec.action


class ComponentTarget:
    """A loaded lifecycle component as matchers and StateTransition events see it
    (``matches_node_name`` reads ``node_name``, its full name)."""

    __slots__ = ("container", "node_name")

    def __init__(self, node_name: str, container: str) -> None:
        self.node_name = node_name
        self.container = container

    def __repr__(self) -> str:
        return f"<component {self.node_name} in {self.container}>"


class Outcome(Record):
    """A transition result, with why it was asked for: a record on the supervisor's stream."""

    __slots__ = ("reason", "result", "shutdown_on_failure")

    def __init__(
        self, result: TransitionResult, reason: str, shutdown_on_failure: bool = False
    ) -> None:
        self.result = result
        self.reason = reason  # autostart, sequence, respawn, event, shutdown
        self.shutdown_on_failure = shutdown_on_failure


class LifecycleManager(Part):
    """Drives the launch's managed nodes; lives in the supervisor's loop thread."""

    def __init__(
        self,
        supervisor: DrivenRun,
        *,
        sequences: Iterable[SequenceStep] = (),
        timeout: float = DEFAULT_TIMEOUT,
        deactivate_timeout: float = DEACTIVATE_TIMEOUT,
    ) -> None:
        self.supervisor = supervisor
        self.timeout = timeout
        self.deactivate_timeout = deactivate_timeout
        self.sequences = list(sequences)
        self.nodes: dict[str, Managed] = {}
        self.outcomes: list[Outcome] = []
        self.activation_order: list[str] = []
        self.loop = LoopCall(supervisor.selector)
        self.graph = SharedGraph(_graph_environ(supervisor), f"_mlaunch_lifecycle_{os.getpid()}")
        self._threads: list[threading.Thread] = []
        self._released = True
        self._held: list[Process] = []
        self._in_sequence = {name for seq in self.sequences for name in seq.nodes}
        for spec in supervisor.plan.processes():
            self._track(spec)
        supervisor.records.subscribe(self.on_record)
        self._check_sequences()
        if self.sequences:
            # First thing in the loop, after the plan's processes are started.
            supervisor.schedule(0.0, self._start_sequences, keeps_alive=False)

    def _check_sequences(self) -> None:
        """Warn about sequence names no LifecycleNode of the plan has (a typo, a namespace)."""
        known = sorted(self.nodes)
        for seq in self.sequences:
            for name in seq.nodes:
                if name not in self.nodes:
                    self._say(
                        "WARNING",
                        f"lifecycle sequence ({seq.origin}) names {name}, which no LifecycleNode"
                        f" of this launch has (they are: {', '.join(known) or 'none'});"
                        " waiting for it anyway",
                    )

    def _say(self, level: str, text: str) -> None:
        self.supervisor.records.emit(Said(level, SOURCE, text))

    def _track(self, spec: ProcessSpec) -> Managed | None:
        info = spec.node
        if info is None or not info.lifecycle or not info.fully_qualified_name:
            return None
        fqn = info.fully_qualified_name
        managed = self.nodes.get(fqn)
        if managed is None or managed.spec is not spec:
            drive = (
                "sequence" if fqn in self._in_sequence else ("autostart" if info.autostart else "")
            )
            managed = Managed(fqn, spec, drive)
            self.nodes[fqn] = managed
        return managed

    # --- the supervisor's events (loop thread) -------------------------------------------------

    def on_record(self, record: Record) -> None:
        """The subscription: processes starting and exiting, ChangeState, the shutdown.

        A manager attached during the run is handed the record that showed it was needed.
        """
        if isinstance(record, Started):
            self._on_process(False, record.process)
        elif isinstance(record, Exited):
            self._on_process(True, record.process)
        elif isinstance(record, ComponentLoaded):
            self._on_loaded(record)
        elif isinstance(record, ShutdownBegun):
            self._on_shutdown()
        elif isinstance(record, LaunchEvent):
            from mlaunch.launch_ros.events.lifecycle.change_state import ChangeState

            if isinstance(record.event, ChangeState):
                record.taken = True
                self._on_change_state(record.event)

    def _on_process(self, exited: bool, process: ProcessView) -> None:
        if exited:
            # The components it hosted are gone with it (a new container loads none of them).
            for hosted in self.nodes.values():
                if hosted.component is not None and hosted.process is process:
                    self._gone(hosted)
        managed = self._track(process.spec)
        if managed is None:
            return
        if exited:
            self._gone(managed)
            return
        managed.process = process
        reason = ""
        if managed.drive == "autostart" or (managed.drive == "sequence" and managed.brought_up):
            reason = "respawn" if process.restarts else "autostart"
        self._spawn(self._started, managed, managed.generation, reason)

    def _gone(self, managed: Managed) -> None:
        managed.process = None
        managed.generation += 1
        managed.state = "gone"
        if managed.fqn in self.activation_order:
            self.activation_order.remove(managed.fqn)

    def _on_loaded(self, event: ComponentLoaded) -> None:
        """A container loaded a component to autostart: bring it up, as an autostart node."""
        target = getattr(event.step, "target", "")
        container = next(
            (
                p
                for p in self.supervisor.processes
                if p.running
                and p.spec.node is not None
                and p.spec.node.fully_qualified_name == target
            ),
            None,
        )
        if container is None:
            self._say(
                "WARNING",
                f"lifecycle component {event.name} was loaded into {target}, which is no process"
                " of this launch: it is not brought up (start its container in the launch)",
            )
            return
        managed = self.nodes.get(event.name)
        if managed is None or managed.component is None:
            managed = Managed(event.name, container.spec, "autostart")
            managed.component = ComponentTarget(event.name, target)
            self.nodes[event.name] = managed
        else:
            managed.spec = container.spec
            managed.generation += 1  # a reload: an earlier bring-up's result is stale
        managed.process = container
        self._spawn(self._started, managed, managed.generation, "autostart")

    def _start_sequences(self) -> None:
        for seq in self.sequences:
            self._spawn(self._run_sequence, seq)

    def _spawn(self, target: Callable[..., None], *args: Any) -> None:
        if self.supervisor.shutting_down and target != self._deactivate_all:
            return
        thread = threading.Thread(target=target, args=args, daemon=True, name="mlaunch-lifecycle")
        self._threads = [t for t in self._threads if t.is_alive()]
        self._threads.append(thread)
        thread.start()

    # --- worker threads -------------------------------------------------------------------------

    def _started(self, managed: Managed, generation: int, reason: str) -> None:
        """A lifecycle node's process started: watch its transitions, bring it up if asked."""
        graph = self._graph_or_report(managed.fqn)
        if graph is None:
            return
        if not managed.subscribed:
            # Subscribed before the first transition is asked for, so handlers see all of them.
            managed.subscribed = True
            fqn = managed.fqn
            try:
                graph.on_transition(
                    fqn, lambda ev: self.loop.call_soon(lambda: self._transition(ev))
                )
            except Exception as exc:
                self._post_note("ERROR", f"cannot watch {fqn}/transition_event: {exc}")
        if not reason:
            return
        outcome = self._bring_up(managed.fqn, reason, self.timeout, managed.required)
        if outcome is not None and outcome.result.ok:
            self.loop.call_soon(lambda: self._up(managed.fqn, generation))

    def _run_sequence(self, seq: SequenceStep) -> None:
        for fqn in seq.nodes:
            outcome = self._bring_up(fqn, "sequence", seq.timeout, seq.shutdown_on_failure)
            if outcome is None or not outcome.result.ok:
                return
            managed = self.nodes.get(fqn)
            generation = managed.generation if managed is not None else 0
            self.loop.call_soon(lambda fqn=fqn, g=generation: self._up(fqn, g))  # type: ignore[misc]
        names = ", ".join(seq.nodes)
        self._post_note("INFO", f"lifecycle sequence complete: {names} active")

    def _bring_up(
        self, fqn: str, reason: str, timeout: float, shutdown_on_failure: bool
    ) -> Outcome | None:
        """Query the state, then ask for what is missing up to 'active'; None if cancelled."""
        from mlaunch.parts.bridge import GraphNotRunning, RosBridgeError, TransitionResult

        graph = self._graph_or_report(fqn)
        if graph is None:
            return None
        try:
            state = self._wait_state(graph, fqn, time.monotonic() + timeout)
        except GraphNotRunning:
            return None
        except RosBridgeError as exc:
            result = TransitionResult(False, fqn, "configure", f"{fqn}: {exc}")
            return self._post(Outcome(result, reason, shutdown_on_failure))
        steps = TO_ACTIVE.get(state)
        if steps is None:
            detail = f"{fqn} is {state!r}; only an unconfigured or inactive node can be brought up"
            result = TransitionResult(False, fqn, "configure", detail, state)
            return self._post(Outcome(result, reason, shutdown_on_failure))
        outcome = Outcome(TransitionResult(True, fqn, "activate", f"{fqn} is already active"), "")
        for label in steps:
            if self.supervisor.shutting_down:
                return None
            try:
                result = graph.change_state(fqn, label, timeout)
            except GraphNotRunning:
                return None
            outcome = self._post(Outcome(result, reason, shutdown_on_failure))
            if not result.ok:
                break
        return outcome

    def _wait_state(self, graph: RosGraph, fqn: str, deadline: float) -> str:
        """The node's state, asking again every STATE_ATTEMPT seconds until the deadline.

        A respawned node's old get_state server can still look available (its death not yet
        noticed by DDS) while the new one has not matched our client yet: a request sent then
        is lost. Asking again is harmless, as get_state changes nothing.
        """
        from mlaunch.parts.bridge import RosTimeout

        while True:
            left = deadline - time.monotonic()
            try:
                return graph.lifecycle_state(fqn, max(0.1, min(STATE_ATTEMPT, left)))
            except RosTimeout:
                if time.monotonic() >= deadline or self.supervisor.shutting_down:
                    raise

    def _graph_or_report(self, fqn: str) -> RosGraph | None:
        from mlaunch.parts.bridge import GraphNotRunning, RosBridgeError

        try:
            return self.graph.get()
        except GraphNotRunning:
            return None
        except RosBridgeError as exc:
            self._post_note("ERROR", f"cannot drive lifecycle node {fqn}: {exc}")
            return None

    def _post(self, outcome: Outcome) -> Outcome:
        self.loop.call_soon(lambda: self._record(outcome))
        return outcome

    def _post_note(self, level: str, text: str) -> None:
        self.loop.call_soon(lambda: self._say(level, text))

    # --- results (loop thread) ------------------------------------------------------------------

    def _record(self, outcome: Outcome) -> None:
        self.outcomes.append(outcome)
        result = outcome.result
        managed = self.nodes.get(result.node)
        if managed is not None and result.state:
            managed.state = result.state
        if result.ok:
            self._say("INFO", result.detail)
        elif self.supervisor.shutting_down and outcome.reason != "shutdown":
            self._say("INFO", f"{result.detail} (the launch is shutting down)")
        else:
            why = f" [{outcome.reason}]" if outcome.reason else ""
            self._say("ERROR", f"transition failed{why}: {result.detail}")
            if outcome.shutdown_on_failure and outcome.reason != "shutdown":
                self.supervisor.exit_status(EXIT_FAILURE)
                self.supervisor.begin_shutdown(
                    f"lifecycle node {result.node}: {result.transition} failed"
                )
        self.supervisor.records.emit(outcome)  # the smoke checks see each result

    def _up(self, fqn: str, generation: int) -> None:
        managed = self.nodes.get(fqn)
        if managed is None or managed.generation != generation:
            return
        managed.brought_up = True
        managed.state = "active"
        if fqn in self.activation_order:
            self.activation_order.remove(fqn)
        self.activation_order.append(fqn)

    def _transition(self, event: Any) -> None:
        """A ``transition_event`` message: track the state, fire OnStateTransition handlers."""
        from mlaunch.launch_ros.events.lifecycle.state_transition import StateTransition

        managed = self.nodes.get(event.node)
        if managed is None:
            return
        managed.state = event.goal_state
        if event.goal_state == "active" and event.node not in self.activation_order:
            self.activation_order.append(event.node)
        elif event.goal_state != "active" and event.node in self.activation_order:
            self.activation_order.remove(event.node)
        transition = StateTransition(
            action=managed.action,
            transition=event.transition,
            start_state=event.start_state,
            goal_state=event.goal_state,
        )
        # OnStateTransition handlers fire on it (mlaunch.engine.handlers).
        self.supervisor.records.emit(Transition(managed.spec, transition))

    def _on_change_state(self, event: Any) -> None:
        """``EmitEvent(event=ChangeState(...))``: the transition, for each matched running node."""
        label = TRANSITION_LABELS.get(event.transition_id)
        if label is None:
            self._say(
                "WARNING",
                f"{event!r}: transition {event.transition_id} cannot be requested from a node;"
                f" valid ids: {', '.join(f'{k} ({v})' for k, v in TRANSITION_LABELS.items())}",
            )
            return
        matched = [m for m in self.nodes.values() if m.process is not None and _matches(event, m)]
        if not matched:
            self._say("WARNING", f"{event!r} matched no running lifecycle node")
            return
        for managed in matched:
            self._spawn(self._change, managed, label)

    # --- runtime control (mlaunch.parts.control, loop thread) ----------------------------------

    def listed(self) -> list[dict[str, object]]:
        """Every lifecycle node of the run: name, label of its process, state (loop thread)."""
        return [
            {
                "name": m.fqn,
                "label": m.spec.label,
                "state": m.state if m.process is not None else "not running",
            }
            for m in self.nodes.values()
        ]

    def find(self, name: str) -> Managed | None:
        """The lifecycle node ``name`` (its full name, its name alone, or its process's label)."""
        named = [m for m in self.nodes.values() if name in (m.fqn, m.spec.label)] or [
            m for m in self.nodes.values() if m.fqn.rsplit("/", 1)[-1] == name
        ]
        return named[0] if len(named) == 1 else None

    def request(
        self, managed: Managed, label: str, done: Callable[[dict[str, object]], None]
    ) -> None:
        """Ask ``managed`` for the transition ``label`` (a user's request: a failure is said,
        it ends nothing); ``done(result)`` on the loop thread once the node answered."""

        def change() -> None:
            from mlaunch.parts.bridge import GraphNotRunning

            graph = self._graph_or_report(managed.fqn)
            result: TransitionResult | None = None
            if graph is not None:
                try:
                    result = graph.change_state(managed.fqn, label, self.timeout)
                except GraphNotRunning:
                    result = None
            self.loop.call_soon(lambda: answered(result))

        def answered(result: TransitionResult | None) -> None:
            if result is None:
                done(
                    {
                        "name": managed.fqn,
                        "transition": label,
                        "ok": False,
                        "error": "the run's ROS graph is not running",
                    }
                )
                return
            self._record(Outcome(result, "user"))
            done(
                {
                    "name": managed.fqn,
                    "transition": label,
                    "ok": result.ok,
                    "state": managed.state,
                    "error": "" if result.ok else result.detail,
                }
            )

        self._spawn(change)

    def _change(self, managed: Managed, label: str) -> None:
        from mlaunch.parts.bridge import GraphNotRunning

        graph = self._graph_or_report(managed.fqn)
        if graph is None:
            return
        try:
            result = graph.change_state(managed.fqn, label, self.timeout)
        except GraphNotRunning:
            return
        self._post(Outcome(result, "event", managed.required))

    # --- shutdown ----------------------------------------------------------------------------

    def _on_shutdown(self) -> None:
        """Hold the active nodes' processes back from the stop ladder while they deactivate.

        On ShutdownBegun: the ladder starts at the StoppingAll that follows it.
        """
        targets = [
            self.nodes[fqn]
            for fqn in reversed(self.activation_order)
            if fqn in self.nodes and self.nodes[fqn].process is not None
        ]
        from mlaunch.engine.process import Process

        # The records name processes by their view; the supervisor holds its own Process objects.
        held: list[Process] = []
        for m in targets:  # a container of several components is held once
            if isinstance(m.process, Process) and m.process.running and m.process not in held:
                held.append(m.process)
        if not held or not self.graph.started:
            return
        # They keep running until _release() hands them to the ladder.
        for process in held:
            self.supervisor.hold_stop(process)
        self._held = held
        self._released = False
        bound = self.deactivate_timeout * len(held) + 1.0
        self.supervisor.schedule(bound, self._release, cancel_on_shutdown=False)
        self._spawn(self._deactivate_all, [m.fqn for m in targets])

    def _deactivate_all(self, names: list[str]) -> None:
        from mlaunch.parts.bridge import GraphNotRunning

        try:
            graph = self.graph.get()
            for fqn in names:
                result = graph.change_state(fqn, "deactivate", self.deactivate_timeout)
                self._post(Outcome(result, "shutdown"))
        except GraphNotRunning:
            return
        finally:
            self.loop.call_soon(self._release)

    def _release(self) -> None:
        if self._released:
            return
        self._released = True
        for process in self._held:
            self.supervisor.release_stop(process)
        self._held = []

    def close(self) -> None:
        self.loop.close()
        self.graph.close()
        for thread in self._threads:
            thread.join(timeout=1.0)


def _matches(event: Any, managed: Managed) -> bool:
    """launch_ros matchers take the LifecycleNode action; mlaunch's also take the ProcessSpec."""
    matcher = event.lifecycle_node_matcher
    if managed.component is not None:
        targets: tuple[Any, ...] = (managed.component,)
    else:
        targets = (managed.spec, managed.spec.action)
    for target in targets:
        try:
            if matcher(target):
                return True
        except Exception:
            continue
    return False


def _graph_environ(supervisor: DrivenRun) -> dict[str, str]:
    """The environment the managed nodes get (their ROS_DOMAIN_ID): a lifecycle node's, else
    the first process's (a container of lifecycle components), else mlaunch's own."""
    processes = supervisor.plan.processes()
    for spec in processes:
        if spec.node is not None and spec.node.lifecycle:
            return dict(spec.env)
    return dict(processes[0].env) if processes else dict(os.environ)


# --- attaching -----------------------------------------------------------------------------------


def attach(arguments: Mapping[str, str], supervisor: DrivenRun) -> LifecycleManager:
    """The pipeline's lifecycle part: a manager with the plan's sequences (and the argument's).

    ``arguments``: the command line's launch arguments (``mlaunch_lifecycle_sequence:=...``).
    """
    plan = supervisor.plan
    sequences = [s for s in plan.steps if isinstance(s, SequenceStep)]
    from_argument = sequence_from_arguments(plan.arguments, arguments)
    if from_argument is not None:
        sequences.append(from_argument)
    return LifecycleManager(supervisor, sequences=sequences)


__all__ = [
    "DEFAULT_TIMEOUT",
    "LifecycleManager",
    "LifecycleSequence",
    "LoopCall",
    "SequenceStep",
    "attach",
]
