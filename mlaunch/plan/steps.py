"""The Plan: what resolving a launch description produces, and the only thing the supervisor runs.

A Plan is an ordered list of steps (start this process, print this line, arm this timer, listen
for this event, shut down). Anything that depends on run time is a step carrying a ``Deferred``:
entities plus the context captured where they were written, resolved by the same resolver when
the trigger fires.

The classes are plain classes with ``__slots__``, not dataclasses: importing dataclasses costs
~8 ms (it imports inspect, ast, dis and tokenize) and creating each dataclass ~0.4 ms, all before
the first child starts. ``Value`` (mlaunch.plan.value) gives them a dataclass's equality and repr.
"""

from __future__ import annotations

import enum  # re imports it: nothing more on the way to the first child

from mlaunch.plan.value import Value

# typing is imported by type checkers only (~4 ms at start-up); mypy treats this name as
# typing.TYPE_CHECKING.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from mlaunch.plan.machine import MachineSpec

# The run state's key (LaunchContext.run_state) for --machine NAME: this run starts that machine's
# share of the launch (mlaunch.plan.machine).
SHARE = "share"

OUTPUT_MODES = ("log", "screen", "both", "own_log", "full")
RESPAWN_MODES = ("never", "always", "on-failure")


class RespawnPolicy(Value):
    """When and how a process is started again after it exits (immutable and hashable).

    ``mode`` is ``never``, ``always`` (ROS 2's respawn=True: any exit) or ``on-failure``
    (non-zero status or a signal). The delay doubles after each quick failure up to
    ``max_delay`` (crash-loop backoff); ``max_retries`` -1 means no limit.
    """

    _fields = ("mode", "delay", "max_retries", "backoff", "max_delay")
    __slots__ = _fields
    # What the slots hold, for type checkers: __init__ sets them without ``self.x = ...``.
    mode: str
    delay: float
    max_retries: int
    backoff: float
    max_delay: float

    def __init__(
        self,
        mode: str = "never",
        delay: float = 0.0,
        max_retries: int = -1,
        backoff: float = 1.0,
        max_delay: float = 30.0,
    ) -> None:
        # Frozen: the supervisor and every respawn share one policy object.
        init = object.__setattr__
        init(self, "mode", mode)
        init(self, "delay", delay)
        init(self, "max_retries", max_retries)
        init(self, "backoff", backoff)
        init(self, "max_delay", max_delay)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"cannot assign to field {name!r} of a RespawnPolicy (it is frozen)")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"cannot delete field {name!r} of a RespawnPolicy (it is frozen)")

    def __hash__(self) -> int:
        return hash(self._values())

    def __reduce__(self) -> tuple[type[RespawnPolicy], tuple[Any, ...]]:
        # Made again through __init__: pickle's default sets the slots, which a frozen class
        # refuses (a cached plan holds its processes' policies).
        return (RespawnPolicy, self._values())

    def describe(self) -> str:
        if self.mode == "never":
            return "no"
        retries = "unlimited" if self.max_retries < 0 else f"at most {self.max_retries}"
        text = f"{self.mode}, delay {self.delay:g} s, {retries} restarts"
        if self.backoff > 1.0:
            text += f", backoff x{self.backoff:g} up to {self.max_delay:g} s"
        return text


class NodeInfo(Value):
    """What the ROS layer knows about a process that is a ROS node."""

    _fields = ("name", "namespace", "package", "executable", "lifecycle", "autostart")
    __slots__ = _fields

    def __init__(
        self,
        name: str | None,
        namespace: str,
        package: str | None,
        executable: str,
        lifecycle: bool = False,
        autostart: bool = False,
    ) -> None:
        self.name = name
        self.namespace = namespace
        self.package = package
        self.executable = executable
        self.lifecycle = lifecycle
        self.autostart = autostart

    @property
    def fully_qualified_name(self) -> str | None:
        if not self.name:
            return None
        ns = self.namespace.rstrip("/")
        return f"{ns}/{self.name}"


class ProcessSpec(Value):
    """Everything needed to start, watch and stop one process. Respawns reuse it unchanged."""

    _fields = (
        "label",
        "argv",
        "env",
        "env_changes",
        "cwd",
        "shell",
        "emulate_tty",
        "output",
        "respawn",
        "sigterm_timeout",
        "sigkill_timeout",
        "required",
        "on_exit",
        "origin",
        "action",
        "node",
        "standin",
        "temp_files",
        "machine",
        "launch_prefix",
        "announce",
        "prepare",
    )
    __slots__ = _fields

    def __init__(
        self,
        label: str,
        argv: tuple[str, ...],
        env: dict[str, str],
        env_changes: dict[str, str | None],
        cwd: str | None = None,
        shell: bool = False,
        emulate_tty: bool = False,
        output: str = "log",
        respawn: RespawnPolicy | None = None,
        sigterm_timeout: float = 5.0,
        sigkill_timeout: float = 5.0,
        required: bool = False,
        on_exit: Deferred | None = None,
        origin: str = "",
        action: Any = None,
        node: NodeInfo | None = None,
        standin: str | None = None,
        temp_files: tuple[str, ...] = (),
        machine: MachineSpec | None = None,
        launch_prefix: tuple[str, ...] = (),
        announce: bytes | None = None,
        prepare: Callable[[ProcessSpec], None] | None = None,
    ) -> None:
        self.label = label
        self.argv = argv
        self.env = env
        self.env_changes = env_changes
        self.cwd = cwd
        self.shell = shell
        self.emulate_tty = emulate_tty  # stdout and stderr are pseudo-terminals (launch's pty)
        self.output = output
        self.respawn: RespawnPolicy = RespawnPolicy() if respawn is None else respawn
        self.sigterm_timeout = sigterm_timeout
        self.sigkill_timeout = sigkill_timeout
        self.required = required
        self.on_exit = on_exit
        self.origin = origin
        self.action = action
        self.node = node
        self.standin = standin
        self.temp_files = temp_files
        # Where it runs: None for this computer, else a declared machine (mlaunch.machines).
        self.machine = machine
        # The launch prefix's words at the head of argv (--launch-prefix, prefix=), for --print.
        self.launch_prefix = launch_prefix
        # The start of the stdout lines in which the program says where to reach it (a stand-in
        # viewer's page): mlaunch says those lines itself, in every output mode and under -q.
        self.announce = announce
        # Called with the spec before each start (a stand-in viewer keeps its port across
        # restarts, so an open page keeps working).
        self.prepare = prepare

    @property
    def base_name(self) -> str:
        return self.label.rsplit("-", 1)[0]


class Deferred(Value):
    """Entities to resolve later: with the run's live context when they fire (launch's rule;
    ``captured`` then holds the values where they were written, to warn where those differ),
    or with a ``context`` frozen where they were written (``captured`` None;
    mlaunch.resolve.binding).
    """

    _fields = ("entities", "context", "origin", "callback", "captured")
    __slots__ = _fields

    def __init__(
        self,
        entities: list[Any],
        context: object,  # the launch API's LaunchContext (live, or a snapshot)
        origin: str = "",
        callback: Any = None,  # callable(event, context) -> entities, as ROS 2 handlers accept
        captured: object | None = None,  # a LaunchContext snapshot, with the live context
    ) -> None:
        self.entities = entities
        self.context = context
        self.origin = origin
        self.callback = callback
        self.captured = captured

    def describe(self) -> str:
        if self.callback is not None:
            describe = getattr(self.callback, "describe", None)
            if callable(describe):  # a callable object that says what it does
                return str(describe())
            name = getattr(self.callback, "__qualname__", repr(self.callback))
            return f"call {name}()"
        return ", ".join(_entity_name(e) for e in self.entities) or "nothing"


def _entity_name(entity: Any) -> str:
    describe = getattr(entity, "describe_short", None)
    return describe() if describe else type(entity).__name__


class Step(Value):
    """One thing the supervisor does, in plan order."""

    _fields: tuple[str, ...] = ("origin",)
    __slots__ = _fields

    def __init__(self, origin: str = "") -> None:
        self.origin = origin


class Spawn(Step):
    __slots__ = ("spec",)
    _fields = (*Step._fields, "spec")

    def __init__(self, origin: str = "", spec: ProcessSpec | None = None) -> None:
        self.origin = origin
        self.spec = spec


class Log(Step):
    __slots__ = ("level", "message", "source")
    _fields = (*Step._fields, "level", "source", "message")

    def __init__(
        self,
        origin: str = "",
        level: str = "INFO",
        source: str = "launch.user",
        message: str = "",
    ) -> None:
        self.origin = origin
        self.level = level
        self.source = source
        self.message = message


class RosClock:
    """launch's own ROS clock, one per run: whether it follows simulated time (/clock).

    SetUseSimTime sets ``simulated``; a ROSTimer's StartTimer holds the run's clock, and the
    engine asks it when it starts the timer (``StartTimer.on_sim_time``), so a SetUseSimTime
    after the timer in the same description counts, as in launch_ros. The one place that says
    whether a run's ROS time is simulated (``ros_clock`` finds it in the run's state).
    """

    __slots__ = ("simulated",)

    def __init__(self) -> None:
        self.simulated = False


# The key of ``LaunchContext.run_state`` that holds the run's RosClock.
ROS_CLOCK_STATE = "ros_clock"


def ros_clock(run_state: dict[str, Any]) -> RosClock:
    """The run's RosClock (made on first use) in its state (``LaunchContext.run_state``)."""
    clock = run_state.get(ROS_CLOCK_STATE)
    if not isinstance(clock, RosClock):
        clock = run_state[ROS_CLOCK_STATE] = RosClock()
    return clock


class StartTimer(Step):
    """Run ``body`` after ``period`` seconds of wall-clock time, or of ROS time for a ROSTimer
    (``ros_clock``: the run's, which says at start whether that time is simulated)."""

    __slots__ = ("action", "body", "cancel_on_shutdown", "period", "ros_clock")
    _fields = (*Step._fields, "period", "body", "cancel_on_shutdown", "action")

    def __init__(
        self,
        origin: str = "",
        period: float = 0.0,
        body: Deferred | None = None,
        cancel_on_shutdown: bool = True,
        action: Any = None,
        ros_clock: RosClock | None = None,
    ) -> None:
        self.origin = origin
        self.period = period
        self.body = body
        self.cancel_on_shutdown = cancel_on_shutdown
        self.action = action  # the TimerAction (OnExecutionComplete targets it)
        self.ros_clock = ros_clock

    @property
    def on_sim_time(self) -> bool:
        """A ROSTimer whose clock is simulated time (/clock) at this moment."""
        return self.ros_clock is not None and self.ros_clock.simulated


class AddHandler(Step):
    """Listen for an event: ``kind`` is process_start, process_exit, process_io, shutdown, ..."""

    __slots__ = ("body", "handler", "io_callbacks", "kind", "matcher", "once")
    _fields = (*Step._fields, "kind", "matcher", "body", "io_callbacks", "once", "handler")

    def __init__(
        self,
        origin: str = "",
        kind: str = "",
        matcher: Any = None,  # callable(ProcessSpec) -> bool, or None for every process
        body: Deferred | None = None,
        io_callbacks: dict[str, Any] | None = None,
        once: bool = False,
        handler: Any = None,  # the user's handler object (for UnregisterEventHandler)
    ) -> None:
        self.origin = origin
        self.kind = kind
        self.matcher = matcher
        self.body = body
        self.io_callbacks: dict[str, Any] = {} if io_callbacks is None else io_callbacks
        self.once = once
        self.handler = handler


class RemoveHandler(Step):
    __slots__ = ("handler",)
    _fields = (*Step._fields, "handler")

    def __init__(self, origin: str = "", handler: Any = None) -> None:
        self.origin = origin
        self.handler = handler


class RequestShutdown(Step):
    """Shut the run down. ``due_to_sigint``: the Shutdown event said so (OnShutdown handlers
    see it); ``send_sigint``: whether the stop ladder starts with SIGINT. launch leaves SIGINT
    out for a Shutdown due to SIGINT in an interactive launch (the terminal is taken to have
    sent it to the process group): SIGTERM then comes after ``sigterm_timeout``. ``status``:
    the run's exit status is at least this (0 for launch's Shutdown; a native ROS 1 run whose
    parameter server cannot be loaded ends with 1, as roslaunch)."""

    __slots__ = ("due_to_sigint", "reason", "send_sigint", "status")
    _fields = (*Step._fields, "reason", "due_to_sigint", "send_sigint", "status")

    def __init__(
        self,
        origin: str = "",
        reason: str = "reason not given",
        due_to_sigint: bool = False,
        send_sigint: bool = True,
        status: int = 0,
    ) -> None:
        self.origin = origin
        self.reason = reason
        self.due_to_sigint = due_to_sigint
        self.send_sigint = send_sigint
        self.status = status


class EmitEvent(Step):
    """An event other than Shutdown (ShutdownProcess, SignalProcess, lifecycle ChangeState...)."""

    __slots__ = ("event",)
    _fields = (*Step._fields, "event")

    def __init__(self, origin: str = "", event: Any = None) -> None:
        self.origin = origin
        self.event = event


class Note(Step):
    """A step the supervisor carries nothing out for, read from the plan by what attaches to it.

    A lifecycle sequence, a smoke-test expectation. Any other step kind the supervisor does not
    know is an error, not skipped.
    """


class Elsewhere(Note):
    """A step of another machine's share (``--machine NAME``): not carried out in this run.

    ``spec`` is the process another run starts (its label is counted here as in the whole
    launch, so labels and log names match), or ``step`` a load into a container that run starts;
    ``share`` is the machine that runs it (``local``: the processes given no machine).
    """

    __slots__ = ("share", "spec", "step")
    _fields = (*Step._fields, "share", "spec", "step")

    def __init__(
        self,
        origin: str = "",
        share: str = "",
        spec: ProcessSpec | None = None,
        step: Step | None = None,
    ) -> None:
        self.origin = origin
        self.share = share
        self.spec = spec
        self.step = step

    @property
    def container(self) -> str | None:
        """The container a load is into (a Handoff's ``target``), None for a process."""
        target = getattr(self.step, "target", None)
        return target if isinstance(target, str) else None

    def describe(self) -> str:
        if self.spec is not None:
            where = "is given no machine" if self.share == "local" else f"runs on {self.share}"
            return (
                f"{self.spec.label} {where}: not started by this run"
                f" (mlaunch FILE --machine {self.share} starts it)"
            )
        return (
            f"the load into {self.container} is done by the run that starts that container"
            " (a container the launch does not start: the local share's run)"
        )


class Handoff(Step):
    """A step carried out by a part attached to the run, whenever it is reached.

    The supervisor emits it on the record stream (``HandedOff``) as it carries out the plan, a
    timer's or a handler's steps alike, so the part acting on it (``needs`` names it: the
    LoadNode driver for LoadComponents) sees every such step once, in order. A handoff no part
    takes is said, never dropped in silence.
    """

    @property
    def needs(self) -> frozenset[Need]:
        """The part that acts on it (a subclass names it)."""
        return frozenset()


class Need(enum.Enum):
    """What a run may need attached besides the supervisor (``Plan.needs``, a step's or an
    entity's ``needs``): the part the application attaches for it."""

    LIFECYCLE = "lifecycle"  # lifecycle driving (mlaunch.parts.lifecycle)
    COMPONENTS = "components"  # the LoadNode driver (mlaunch.parts.components)


NO_NEEDS: frozenset[Need] = frozenset()
LIFECYCLE: frozenset[Need] = frozenset({Need.LIFECYCLE})
COMPONENTS: frozenset[Need] = frozenset({Need.COMPONENTS})


# The YAML/XML form of a LifecycleSequence: a launch argument listing the nodes.
SEQUENCE_ARGUMENT = "mlaunch_lifecycle_sequence"


def step_needs(step: Step) -> frozenset[Need]:
    """What a step needs attached to the run: a lifecycle node's spawn, a ChangeState, an
    OnStateTransition handler and a LifecycleSequence need lifecycle driving."""
    if isinstance(step, Spawn):
        node = step.spec.node if step.spec is not None else None
        return LIFECYCLE if node is not None and node.lifecycle else NO_NEEDS
    if isinstance(step, AddHandler):
        return frozenset(getattr(step.handler, "needs", NO_NEEDS))
    if isinstance(step, EmitEvent):
        return frozenset(getattr(step.event, "needs", NO_NEEDS))
    return frozenset(getattr(step, "needs", NO_NEEDS))


class ArgumentInfo(Value):
    """A declared launch argument, for --show-args and CLI checks."""

    _fields = (
        "name",
        "default",
        "description",
        "choices",
        "origin",
        "conditional",
        "value",
        "resolved",
        "passed_by",
    )
    __slots__ = _fields

    def __init__(
        self,
        name: str,
        default: str | None,
        description: str,
        choices: tuple[str, ...] | None,
        origin: str,
        conditional: bool = False,
        value: str | None = None,
    ) -> None:
        self.name = name
        self.default = default
        self.description = description
        self.choices = choices
        self.origin = origin
        self.conditional = conditional
        # The value the run gave it where it was first declared (resolve sets it; --show-args
        # does not resolve, so None there).
        self.value = value
        # --show-args: the default worked out before running, when it has substitutions that
        # can be (a package's path); None when it is plain text or cannot be.
        self.resolved: str | None = None
        # --show-args: where an including file passes it (file:line), so it is not required.
        self.passed_by = ""


class Plan(Value):
    """The resolved launch: its steps in order, its arguments, warnings, and ``needs``: what
    must attach to the run (``"lifecycle"``), noted by resolve as it adds and defers steps."""

    _fields = ("steps", "arguments", "warnings", "temp_dir", "needs")
    __slots__ = _fields

    def __init__(
        self,
        steps: list[Step] | None = None,
        arguments: dict[str, ArgumentInfo] | None = None,
        warnings: list[str] | None = None,
        temp_dir: str | None = None,
        needs: set[Need] | None = None,
    ) -> None:
        self.steps: list[Step] = [] if steps is None else steps
        self.arguments: dict[str, ArgumentInfo] = {} if arguments is None else arguments
        self.warnings: list[str] = [] if warnings is None else warnings
        self.temp_dir = temp_dir
        self.needs: set[Need] = set() if needs is None else needs

    def processes(self) -> list[ProcessSpec]:
        return [s.spec for s in self.steps if isinstance(s, Spawn) and s.spec is not None]
