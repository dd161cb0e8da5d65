"""Carrying out a plan's steps: spawns, LogInfo, timers, handlers, events, shutdown, handoffs.

``Executor`` is one object of the Supervisor (mlaunch.engine.supervisor): it carries out the
steps of the plan, and of every timer's and handler's body when it fires (resolved with the same
resolve code, ``resolve``), in plan order. What the steps cause is queued on the record stream
until a description's steps have all been carried out, as launch handles events only after the
description was visited.
"""

from __future__ import annotations

from mlaunch.engine.stopping import handle_stop_signals
from mlaunch.plan.errors import EXIT_USAGE, MlaunchError
from mlaunch.plan.records import (
    Completed,
    HandedOff,
    LaunchEvent,
    Said,
    SimTimeWait,
    StartsSkipped,
    Unclaimed,
)
from mlaunch.plan.steps import (
    AddHandler,
    EmitEvent,
    Handoff,
    Log,
    Note,
    RemoveHandler,
    RequestShutdown,
    Spawn,
    StartTimer,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable

    from mlaunch.engine.handlers import LaunchHandlers
    from mlaunch.engine.signals import SignalWatch
    from mlaunch.engine.stopping import Stopping
    from mlaunch.engine.timers import Timers
    from mlaunch.plan.records import RecordStream
    from mlaunch.plan.steps import Deferred, Plan, ProcessSpec, Step


class Executor:
    """Carries out steps for one run.

    ``start(spec)`` starts a process (the supervisor's); ``resolve(body, event)`` resolves a
    deferred body into a Plan; ``exit_status(code)`` raises the run's exit status.
    """

    def __init__(
        self,
        *,
        records: RecordStream,
        timers: Timers,
        handlers: LaunchHandlers,
        shutdown: Stopping,
        signals: SignalWatch,
        start: Callable[[ProcessSpec], object],
        running: Callable[[ProcessSpec], bool] = lambda spec: False,
        resolve: Callable[[Deferred, object, bool | None], Plan],
        exit_status: Callable[[int], None],
    ) -> None:
        self.records = records
        self.timers = timers
        self.handlers = handlers
        self.shutdown = shutdown
        self.signals = signals
        self.start = start
        # Whether a spec's process runs already (started before the supervisor: adopted by
        # start() even while shutting down, and then stopped with the rest).
        self.running = running
        self.resolve = resolve
        self.exit_status = exit_status
        self._skipped = 0  # starts a description asked for while shutting down
        # Specs (by id) an OnExecutionComplete handler waited for when they were visited.
        self._awaited: set[int] = set()

    def execute(self, steps: list[Step], warnings: list[str] | tuple[str, ...] = ()) -> None:
        """Carry out a visited description's steps.

        What they cause is queued on the record stream until every step has been carried out,
        as launch handles events only after the description was visited: a handler
        registered after a process in the same description still sees it start.
        """
        self.records.hold()
        try:
            for warning in warnings:
                self.records.say_now(Said("WARNING", "launch", warning))
            for step in steps:
                if self.signals.pending:
                    # Hundreds of spawns take seconds: Ctrl-C (and a second one) act now, not
                    # after the last one started. Exits wait for the loop, as in ROS 2.
                    handle_stop_signals(self.signals.pending, self.shutdown.pressed)
                self._step(step)
            if self._skipped:
                self.records.emit(StartsSkipped(self._skipped))  # once, not once per process
                self._skipped = 0
        finally:
            self.records.release()

    def _step(self, step: Step) -> None:
        if isinstance(step, Spawn):
            if step.spec is not None and self.shutdown.active and not self.running(step.spec):
                self._skipped += 1
            elif step.spec is not None:
                if self.handlers.wants_completion(step.spec.action):
                    self._awaited.add(id(step.spec))  # ExecutionComplete once it exits for good
                self.start(step.spec)
        elif isinstance(step, Log):
            # LogInfo is no event in launch: it is said as it is visited.
            self.records.say_now(Said(step.level, step.source, step.message))
        elif isinstance(step, StartTimer):
            self._start_timer(step)
        elif isinstance(step, AddHandler):
            self.handlers.add(step)
        elif isinstance(step, RemoveHandler):
            self.handlers.remove(step.handler)
        elif isinstance(step, RequestShutdown):
            if step.status:
                self.exit_status(step.status)
            self.shutdown.request(
                step.reason,
                due_to_signal=2 if step.due_to_sigint else None,  # SIGINT, as the event said
                send_sigint=step.send_sigint,
            )
        elif isinstance(step, EmitEvent):
            self.records.emit(LaunchEvent(step.event))
        elif isinstance(step, Handoff):
            # For the part that carries it out (the LoadNode driver): from the plan, a timer
            # or a handler alike, in the order the steps are reached.
            handed = HandedOff(step)
            self.records.emit(handed)
            self.records.emit(Unclaimed(handed))
        elif not isinstance(step, Note):
            raise TypeError(
                f"the supervisor cannot carry out a {type(step).__name__} step ({step.origin});"
                " whatever adds this kind of step must also handle it"
            )

    def _start_timer(self, step: StartTimer) -> None:
        body, action = step.body, step.action
        awaited = action is not None and self.handlers.wants_completion(action)
        if body is None and not awaited:
            return

        def expire() -> None:
            if body is not None:
                self.fire(body, None)
            if awaited:
                self.records.emit(Completed(action))

        if step.on_sim_time:
            self._wait_sim_time(step, expire)
        else:
            self._wall_timer(step, expire)

    def _wall_timer(self, step: StartTimer, expire: Callable[[], None]) -> None:
        timer = self.timers.add(step.period, expire, cancel_on_shutdown=step.cancel_on_shutdown)
        timer.holds_shutdown = not step.cancel_on_shutdown

    def _wait_sim_time(self, step: StartTimer, expire: Callable[[], None]) -> None:
        """Hand a ROSTimer on simulated time to the ROS clock part; if none took it (looked at
        once the stream has handed it to every subscriber), say so and count wall-clock time."""
        handed = SimTimeWait(step.origin, step.period, expire, step.cancel_on_shutdown)
        self.records.emit(handed)

        def unless_taken() -> None:
            if handed.taken:
                return
            text = (
                f"{step.origin}: ROSTimer counts its period in wall-clock time: launch's ROS"
                " clock uses simulated time (SetUseSimTime) but nothing in this run reads /clock"
            )
            self.records.emit(Said("WARNING", "launch", text))
            self._wall_timer(step, expire)

        self.timers.add(0.0, unless_taken, cancel_on_shutdown=step.cancel_on_shutdown)

    def ended_for_good(self, spec: ProcessSpec) -> None:
        """``spec``'s process exited and will not restart: ExecutionComplete, if awaited."""
        if id(spec) in self._awaited:
            self._awaited.discard(id(spec))
            self.records.emit(Completed(spec.action))

    def fire(self, body: Deferred, event: object, shutting_down: bool | None = None) -> None:
        """Resolve deferred entities now (timer, handler, on_exit) and run what they give."""
        try:
            plan = self.resolve(body, event, shutting_down)
        except MlaunchError as e:
            self.handler_failed(str(e))
            return
        self.execute(plan.steps, plan.warnings)

    def handler_failed(self, message: str) -> None:
        """A handler of the launch file failed: say where, then shut down (exit status 2)."""
        self.records.emit(Said("ERROR", "launch", message))
        self.exit_status(EXIT_USAGE)
        self.shutdown.begin("an event handler failed")
