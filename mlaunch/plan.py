"""The Plan: what resolving a launch description produces, and the only thing the supervisor runs.

A Plan is an ordered list of steps (start this process, print this line, arm this timer, listen
for this event, shut down). Anything that depends on run time is a step carrying a ``Deferred``:
entities plus the context captured where they were written, resolved by the same resolver when
the trigger fires.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mlaunch.context import LaunchContext

OUTPUT_MODES = ("log", "screen", "both", "own_log", "full")
RESPAWN_MODES = ("never", "always", "on-failure")


@dataclass(frozen=True)
class RespawnPolicy:
    """When and how a process is started again after it exits.

    ``mode`` is ``never``, ``always`` (ROS 2's respawn=True: any exit) or ``on-failure``
    (non-zero status or a signal). The delay doubles after each quick failure up to
    ``max_delay`` (crash-loop backoff); ``max_retries`` -1 means no limit.
    """

    mode: str = "never"
    delay: float = 0.0
    max_retries: int = -1
    backoff: float = 1.0
    max_delay: float = 30.0

    def describe(self) -> str:
        if self.mode == "never":
            return "no"
        retries = "unlimited" if self.max_retries < 0 else f"at most {self.max_retries}"
        text = f"{self.mode}, delay {self.delay:g} s, {retries} restarts"
        if self.backoff > 1.0:
            text += f", backoff x{self.backoff:g} up to {self.max_delay:g} s"
        return text


@dataclass
class NodeInfo:
    """What the ROS layer knows about a process that is a ROS node."""

    name: str | None
    namespace: str
    package: str | None
    executable: str
    lifecycle: bool = False
    autostart: bool = False

    @property
    def fully_qualified_name(self) -> str | None:
        if not self.name:
            return None
        ns = self.namespace.rstrip("/")
        return f"{ns}/{self.name}"


@dataclass
class ProcessSpec:
    """Everything needed to start, watch and stop one process. Respawns reuse it unchanged."""

    label: str
    argv: tuple[str, ...]
    env: dict[str, str]
    env_changes: dict[str, str | None]
    cwd: str | None = None
    shell: bool = False
    output: str = "log"
    respawn: RespawnPolicy = field(default_factory=RespawnPolicy)
    sigterm_timeout: float = 5.0
    sigkill_timeout: float = 5.0
    required: bool = False
    on_exit: Deferred | None = None
    origin: str = ""
    action: Any = None
    node: NodeInfo | None = None
    standin: str | None = None
    temp_files: tuple[str, ...] = ()

    @property
    def base_name(self) -> str:
        return self.label.rsplit("-", 1)[0]


@dataclass
class Deferred:
    """Entities to resolve later, with the context they were written in."""

    entities: list[Any]
    context: LaunchContext
    origin: str = ""
    callback: Any = None  # callable(event, context) -> entities, as ROS 2 handlers accept

    def describe(self) -> str:
        if self.callback is not None:
            name = getattr(self.callback, "__qualname__", repr(self.callback))
            return f"call {name}()"
        return ", ".join(_entity_name(e) for e in self.entities) or "nothing"


def _entity_name(entity: Any) -> str:
    describe = getattr(entity, "describe_short", None)
    return describe() if describe else type(entity).__name__


@dataclass
class Step:
    """One thing the supervisor does, in plan order."""

    origin: str = ""


@dataclass
class Spawn(Step):
    spec: ProcessSpec | None = None


@dataclass
class Log(Step):
    level: str = "INFO"
    source: str = "launch.user"
    message: str = ""


@dataclass
class StartTimer(Step):
    period: float = 0.0
    body: Deferred | None = None
    cancel_on_shutdown: bool = True


@dataclass
class AddHandler(Step):
    """Listen for an event: ``kind`` is process_start, process_exit, process_io, shutdown, ..."""

    kind: str = ""
    matcher: Any = None  # callable(ProcessSpec) -> bool, or None for every process
    body: Deferred | None = None
    io_callbacks: dict[str, Any] = field(default_factory=dict)
    once: bool = False
    handler: Any = None  # the user's handler object (for UnregisterEventHandler)


@dataclass
class RemoveHandler(Step):
    handler: Any = None


@dataclass
class RequestShutdown(Step):
    reason: str = "reason not given"


@dataclass
class EmitEvent(Step):
    """An event other than Shutdown (ShutdownProcess, SignalProcess, lifecycle ChangeState...)."""

    event: Any = None


@dataclass
class ArgumentInfo:
    """A declared launch argument, for --show-args and CLI checks."""

    name: str
    default: str | None
    description: str
    choices: tuple[str, ...] | None
    origin: str
    conditional: bool = False


@dataclass
class Plan:
    steps: list[Step] = field(default_factory=list)
    arguments: dict[str, ArgumentInfo] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    temp_dir: str | None = None

    def processes(self) -> list[ProcessSpec]:
        return [s.spec for s in self.steps if isinstance(s, Spawn) and s.spec is not None]
