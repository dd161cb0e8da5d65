"""The model of the ROS 2 launch description a roslaunch file becomes.

``mlaunch.ros1.reading`` maps a ROS 1 file to these ``Item`` objects (arguments, SetParameter,
groups, includes, nodes, processes, warnings); ``mlaunch.ros1.build`` turns them into mlaunch's
actions and ``mlaunch.commands.convert`` writes them out as a ROS 2 file.
"""

from __future__ import annotations

import ast
import os
from dataclasses import dataclass, field
from typing import Any, Union


@dataclass(frozen=True)
class Ref:
    """A roslaunch substitution inside a value (``$(arg x)``, ``$(find pkg)`` ...)."""


@dataclass(frozen=True)
class ArgRef(Ref):
    """``$(arg name)``: a launch argument (ROS 2 LaunchConfiguration)."""

    name: str


@dataclass(frozen=True)
class FindRef(Ref):
    """``$(find pkg)``: the package's folder (ROS 2 FindPackageShare)."""

    package: str


@dataclass(frozen=True)
class ExecRef(Ref):
    """``$(find pkg)/program`` where it names a program (an argument of another one): the
    program's path (ROS 2 ExecutableInPackage), as roslaunch found it in the package."""

    package: str
    executable: str


@dataclass(frozen=True)
class EnvRef(Ref):
    """``$(env NAME)`` (no default: must be set) or ``$(optenv NAME default)``."""

    name: str
    default: str | None = None


@dataclass(frozen=True)
class AnonRef(Ref):
    """``$(anon name)``: a name unique to this launch."""

    name: str


@dataclass(frozen=True)
class DirnameRef(Ref):
    """``$(dirname)``: the folder of the launch file."""


@dataclass(frozen=True)
class EvalArg:
    """A name an ``$(eval)`` expression reads, and how a converted expression writes it.

    ``kind``: ``raw`` (a number, inserted as is), ``str`` (quoted text), ``bool`` (true/false
    text compared), chosen from the argument's default when the file is read.
    """

    ref: Ref
    kind: str


@dataclass(frozen=True)
class EvalRef(Ref):
    """``$(eval expression)``: roslaunch's Python expression over the launch arguments.

    ``pieces`` is the expression cut at every argument, ``find``, ``env`` ... it reads, for a
    ROS 2 PythonExpression; None when that cannot be written (a computed call argument).
    """

    expression: str
    pieces: tuple[str | EvalArg, ...] | None


@dataclass(frozen=True)
class CommandRef(Ref):
    """``<param command=...>``: the command's standard output (ROS 2 Command)."""

    command: Value


@dataclass(frozen=True)
class FileRef(Ref):
    """``<param textfile=...>``: the file's text (ROS 2 FileContent)."""

    path: Value


Part = Union[str, Ref]  # noqa: UP007
Value = tuple[Part, ...]


@dataclass(frozen=True)
class Cond:
    """An ``if`` (or, with ``unless``, an ``unless``) on an item."""

    value: Value
    unless: bool = False


@dataclass(frozen=True)
class PValue:
    """A parameter value: a typed literal, or substitutions typed when resolved.

    ``vtype`` (str, int, float, bool) forces the type of ``dynamic``; None reads it with ROS 2's
    YAML rules, or with ``auto`` (an untyped ``<param value>``) by roslaunch's rule when mlaunch
    runs the file (a converted ROS 2 file can only say YAML).
    """

    literal: Any = None
    dynamic: Value | None = None
    vtype: type | None = None
    auto: bool = False


Params = list[tuple[Value, PValue]]


@dataclass(kw_only=True)
class Item:
    """One entry of the ROS 2 description: where it was written, its condition, its warnings."""

    origin: str
    condition: Cond | None = None
    warnings: list[str] = field(default_factory=list)
    # warnings about where ROS 2 puts a global parameter by the file's scopes: moot when
    # mlaunch runs the file with its parameter server (ROS 1's name rules), kept in conversions
    scope_notes: list[str] = field(default_factory=list)


@dataclass(kw_only=True)
class Warn(Item):
    """A warning on its own (a skipped tag), shown where the file is resolved."""

    message: str
    scope_note: bool = False


@dataclass(kw_only=True)
class DeclareArg(Item):
    """``<arg name default doc>``: DeclareLaunchArgument (required without a default)."""

    name: str
    default: Value | None
    doc: str | None


@dataclass(kw_only=True)
class SetArg(Item):
    """``<arg name value>``: a constant, SetLaunchConfiguration."""

    name: str
    value: Value


@dataclass(kw_only=True)
class SetParam(Item):
    """A global parameter: SetParameter for every node of the scope."""

    name: Value
    value: PValue


@dataclass(kw_only=True)
class SetRemap(Item):
    src: Value
    dst: Value


@dataclass(kw_only=True)
class SetEnv(Item):
    name: Value
    value: Value


@dataclass(kw_only=True)
class Group(Item):
    """GroupAction (scoped unless said otherwise), with PushROSNamespace when ``namespace``."""

    items: list[Item]
    namespace: Value | None = None
    scoped: bool = True


@dataclass(kw_only=True)
class Include(Item):
    """IncludeLaunchDescription of another file with its arguments."""

    path: Value
    arguments: list[tuple[str, Value]]


@dataclass(kw_only=True)
class MachineItem(Item):
    """``<machine>``: a computer nodes can run on (mlaunch.machines' Machine action)."""

    name: Value
    address: Value
    user: Value | None = None
    ssh_port: Value | None = None
    env_loader: Value | None = None
    default: Value | None = None
    timeout: Value | None = None


# MachineItem's optional fields and their roslaunch attribute names.
MACHINE_FIELDS = (
    ("user", "user"),
    ("ssh_port", "ssh-port"),
    ("env_loader", "env-loader"),
    ("default", "default"),
    ("timeout", "timeout"),
)


@dataclass(kw_only=True)
class Process(Item):
    """Fields a node and a plain process share."""

    output: Value | None = None
    respawn: bool | Value = False
    respawn_delay: float | Value | None = None
    required: bool | Value = False
    prefix: Value | None = None
    env: list[tuple[Value, Value]] = field(default_factory=list)
    machine: Value | None = None


@dataclass(kw_only=True)
class NodeItem(Process):
    """A launch_ros Node."""

    package: Value
    executable: Value
    name: Value | None
    namespace: Value | None = None
    arguments: list[Value] = field(default_factory=list)
    # ``args`` as written when it has substitutions: roslaunch substitutes, then splits (None:
    # ``arguments`` is exact, or a mapping rewrote them)
    shell_args: Value | None = None
    parameters: Params = field(default_factory=list)
    remappings: list[tuple[Value, Value]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    # joint_state_publisher's use_gui: which of jsp and jsp_gui runs (set while reading)
    gui: PValue | None = None


@dataclass(kw_only=True)
class ProcessItem(Process):
    """An ExecuteProcess (a program that is not a ROS node of a package)."""

    cmd: list[Value]
    notes: list[str] = field(default_factory=list)


@dataclass(kw_only=True)
class Dropped(Item):
    """A node that cannot run here; its warning says why (a converted file keeps it, commented)."""

    node: NodeItem


def text(value: str) -> Value:
    return (value,)


def static_text(value: Value | None) -> str | None:
    """The value's text when it holds no substitution, else None."""
    if value is None or any(not isinstance(p, str) for p in value):
        return None
    return "".join(p for p in value if isinstance(p, str))


def arg_names(value: Any) -> set[str]:
    """The launch arguments a value (or a PValue, Cond, list of them) reads."""
    found: set[str] = set()
    if isinstance(value, ArgRef):
        found.add(value.name)
    elif isinstance(value, EvalRef):
        found.update(_eval_names(value.expression))
    elif isinstance(value, CommandRef):
        found |= arg_names(value.command)
    elif isinstance(value, FileRef):
        found |= arg_names(value.path)
    elif isinstance(value, PValue):
        found |= arg_names(value.dynamic)
    elif isinstance(value, Cond):
        found |= arg_names(value.value)
    elif isinstance(value, (tuple, list)):
        for item in value:
            found |= arg_names(item)
    return found


def _eval_names(expression: str) -> set[str]:
    try:
        tree = ast.parse(expression, mode="eval")
    except SyntaxError:
        return set()
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    for call in ast.walk(tree):
        if called_name(call) == "arg" and isinstance(call, ast.Call) and call.args:
            first = call.args[0]
            if isinstance(first, ast.Constant):
                names.add(str(first.value))
    return names


def called_name(node: ast.AST) -> str | None:
    """``f`` for a call ``f(...)`` of a plain name, else None."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        return node.func.id
    return None


def merge(parts: list[Part]) -> Value:
    out: list[Part] = []
    for part in parts:
        if isinstance(part, str):
            if not part:
                continue
            if out and isinstance(out[-1], str):
                out[-1] += part
                continue
        out.append(part)
    return tuple(out) if out else ("",)


def describe_value(value: Value | Any) -> str:
    """A value as roslaunch wrote it (for messages and comments)."""
    if not isinstance(value, tuple):
        return str(value)
    out = []
    for part in value:
        if isinstance(part, str):
            out.append(part)
        elif isinstance(part, ArgRef):
            out.append(f"$(arg {part.name})")
        elif isinstance(part, FindRef):
            out.append(f"$(find {part.package})")
        elif isinstance(part, ExecRef):
            out.append(f"$(find {part.package})/{part.executable}")
        elif isinstance(part, EnvRef):
            out.append(f"$(env {part.name})" if part.default is None else f"$(optenv {part.name})")
        elif isinstance(part, AnonRef):
            out.append(f"$(anon {part.name})")
        elif isinstance(part, DirnameRef):
            out.append("$(dirname)")
        elif isinstance(part, EvalRef):
            out.append(f"$(eval {part.expression})")
        elif isinstance(part, CommandRef):
            out.append(f"`{describe_value(part.command)}`")
        elif isinstance(part, FileRef):
            out.append(f"<{describe_value(part.path)}>")
    return "".join(out)


def rel_origin(origin: str) -> str:
    """An origin relative to the working directory when that is shorter."""
    try:
        rel = os.path.relpath(origin)
    except ValueError:
        return origin
    return origin if rel.startswith("../../") else rel
