"""What reading a roslaunch file keeps while it walks the tags: scopes and global parameters."""

from __future__ import annotations

from dataclasses import dataclass, field

from mlaunch.ros1.model import Cond, Item, NodeItem, PValue, SetParam, Value


@dataclass
class ArgInfo:
    default: Value | None
    constant: bool


@dataclass
class Scope:
    """What reading knows at one place of the file: visible args and the static namespace."""

    ns: str | None  # absolute, None when a namespace above uses substitutions
    args: dict[str, ArgInfo]
    own: set[str] = field(default_factory=set)
    is_ns: bool = False
    is_root: bool = False

    def child(self, ns: str | None, has_ns: bool) -> Scope:
        if not has_ns:
            child_ns = self.ns
        elif ns is None or self.ns is None:
            child_ns = None
        elif ns.startswith("/"):
            child_ns = "/" + ns.strip("/")
        else:
            child_ns = self.ns.rstrip("/") + "/" + ns.strip("/")
        return Scope(child_ns, dict(self.args), is_ns=has_ns)


@dataclass
class Desc:
    """A global parameter the ROS 2 nodes that read it take as their own parameter."""

    kind: str  # "robot_description" or "use_gui"
    value: PValue
    origin: str
    own: Cond | None
    model: str | None = None  # the model file's stem, for the simulator's entity name


@dataclass
class Pending:
    """A global parameter on its way to the scope it belongs to (ROS 1 sets them first)."""

    item: SetParam | Desc
    target: str  # "ns": the nearest <group ns> or the file; "root": the file
    refs: frozenset[str]
    conds: tuple[Cond, ...] = ()


@dataclass
class Consumer:
    """A node that takes a global parameter as its own in ROS 2 (robot_state_publisher ...)."""

    node: NodeItem
    kind: str
    conds: tuple[Cond, ...] = ()


@dataclass
class Out:
    """A scope read: declarations first, then its global parameters, then the rest in order."""

    decls: list[Item] = field(default_factory=list)
    params: list[Item] = field(default_factory=list)
    body: list[Item] = field(default_factory=list)
    pending: list[Pending] = field(default_factory=list)
    consumers: list[Consumer] = field(default_factory=list)

    def items(self) -> list[Item]:
        return [*self.decls, *self.params, *self.body]


class Skip(Exception):
    """A tag that maps to nothing in ROS 2: a warning, not an error."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message
