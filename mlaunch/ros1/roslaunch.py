"""The ROS 1 frontend: a roslaunch XML file (``*.launch``) run on ROS 2 semantics.

Reading goes in two steps, and ``mlaunch convert`` shares the first one:

1. ``read(path)`` parses the XML (roslaunch's tags, attributes and ``$(...)`` args, checked
   where roslaunch checks them) and *maps* it to a small model of the ROS 2 launch description
   it becomes: ``Item`` objects (arguments, SetParameter, groups, includes, nodes, processes,
   warnings). Every ROS 1 -> ROS 2 decision is taken here, once (docs/ros1.md lists them).
2. ``to_actions(items)`` builds that model into mlaunch's own actions (the ROS 2 classes);
   ``mlaunch.ros1.convert`` writes the same model out as a ROS 2 launch file instead. Running the
   ROS 1 file and running its conversion therefore resolve to the same plan.

What has no ROS 2 equivalent becomes a warning naming the file and line: a warning action in
the description (so ``--print`` and runs show it) and a comment in a converted file.
"""

from __future__ import annotations

import ast
import builtins
import copy
import math
import os
import re
import shlex
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Union
from xml.parsers import expat

import yaml

from mlaunch.errors import LaunchFileError, MlaunchError, SubstitutionFailure
from mlaunch.launch.actions import Action, SetLaunchConfiguration
from mlaunch.launch.substitutions import Substitution

if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.run.resolve import Resolver


# --- the model of the ROS 2 description a ROS 1 file becomes -------------------------------------


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
    YAML rules.
    """

    literal: Any = None
    dynamic: Value | None = None
    vtype: type | None = None


Params = list[tuple[Value, PValue]]


@dataclass(kw_only=True)
class Item:
    """One entry of the ROS 2 description: where it was written, its condition, its warnings."""

    origin: str
    condition: Cond | None = None
    warnings: list[str] = field(default_factory=list)


@dataclass(kw_only=True)
class Warn(Item):
    """A warning on its own (a skipped tag), shown where the file is resolved."""

    message: str


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
class Process(Item):
    """Fields a node and a plain process share."""

    output: Value | None = None
    respawn: bool | Value = False
    respawn_delay: float | Value | None = None
    required: bool | Value = False
    prefix: Value | None = None
    env: list[tuple[Value, Value]] = field(default_factory=list)


@dataclass(kw_only=True)
class NodeItem(Process):
    """A launch_ros Node."""

    package: Value
    executable: Value
    name: Value | None
    namespace: Value | None = None
    arguments: list[Value] = field(default_factory=list)
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
        if _called_name(call) == "arg" and isinstance(call, ast.Call) and call.args:
            first = call.args[0]
            if isinstance(first, ast.Constant):
                names.add(str(first.value))
    return names


def _called_name(node: ast.AST) -> str | None:
    """``f`` for a call ``f(...)`` of a plain name, else None."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        return node.func.id
    return None


# --- XML ---------------------------------------------------------------------------------------


@dataclass
class Element:
    """One XML element with its line (roslaunch files are read with positions)."""

    tag: str
    attrs: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    text: list[str] = field(default_factory=list)


def parse_xml(path: str) -> Element:
    """The root element of the file, every element with its line."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise LaunchFileError(f"cannot read launch file: {e.strerror}", where=path)
    parser = expat.ParserCreate()
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        element = Element(tag, dict(attrs), parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop()

    def chars(data: str) -> None:
        if stack:
            stack[-1].text.append(data)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    try:
        parser.Parse(data, True)
    except expat.ExpatError as e:
        raise LaunchFileError(
            f"malformed XML: {expat.ErrorString(e.code)}", where=f"{path}:{e.lineno}"
        )
    return roots[0]


# --- roslaunch's value conversions -----------------------------------------------------------


def convert_value(value: str, type_name: str) -> Any:
    """roslaunch's ``convert_value``: text to the param type (``auto`` guesses as roslaunch)."""
    kind = type_name.lower()
    if kind == "auto":
        try:
            return float(value) if "." in value else int(value)
        except ValueError:
            pass
        if value.lower() in ("true", "false"):
            return value.lower() == "true"
        return value
    if kind in ("str", "string"):
        return value
    if kind == "int":
        return int(value)
    if kind == "double":
        return float(value)
    if kind in ("bool", "boolean"):
        lowered = value.lower().strip()
        if lowered in ("true", "1"):
            return True
        if lowered in ("false", "0"):
            return False
        raise ValueError(f"{value!r} is not a bool (true, false, 1, 0)")
    if kind == "yaml":
        return yaml.load(value, Loader=RosparamLoader)
    raise ValueError(f"unknown type {type_name!r}")


PARAM_TYPES = ("str", "string", "int", "double", "bool", "boolean", "yaml", "auto")
# The ROS 2 type a dynamic value of each roslaunch type is forced to (None: YAML rules).
_VTYPES: dict[str, type | None] = {
    "str": str,
    "string": str,
    "int": int,
    "double": float,
    "bool": bool,
    "boolean": bool,
    "yaml": None,
    "auto": None,
}


def _angle(text: str) -> float:
    """The arithmetic of rosparam's ``rad(...)``: numbers, ``pi``, + - * / ** and parentheses."""
    tree = ast.parse(text, mode="eval")

    def value(node: ast.AST) -> float:
        if isinstance(node, ast.Expression):
            return value(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id == "pi":
            return math.pi
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
            inner = value(node.operand)
            return inner if isinstance(node.op, ast.UAdd) else -inner
        if isinstance(node, ast.BinOp):
            ops = {ast.Add: float.__add__, ast.Sub: float.__sub__, ast.Mult: float.__mul__}
            ops.update({ast.Div: float.__truediv__, ast.Pow: float.__pow__})
            op = ops.get(type(node.op))
            if op is not None:
                return float(op(value(node.left), value(node.right)))
        raise ValueError(f"not an angle expression: {text!r}")

    return value(tree)


class RosparamLoader(yaml.SafeLoader):
    """YAML as rosparam reads it: safe, plus ``rad(pi/2)`` and ``deg(90)`` angles in radians."""


def _radians(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    value = str(loader.construct_scalar(node)).strip()  # type: ignore[arg-type]
    return _angle(value[4:-1] if value.startswith("rad(") else value)


def _degrees(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    value = str(loader.construct_scalar(node)).strip()  # type: ignore[arg-type]
    return float(value[4:-1] if value.startswith("deg(") else value) * math.pi / 180.0


RosparamLoader.add_constructor("!radians", _radians)
RosparamLoader.add_constructor("!degrees", _degrees)
RosparamLoader.add_implicit_resolver("!radians", re.compile(r"^rad\([^\)]*\)$"), ["r"])
RosparamLoader.add_implicit_resolver("!degrees", re.compile(r"^deg\([^\)]*\)$"), ["d"])


# --- reading a file into the model ---------------------------------------------------------------

SUBSTITUTION_ARITY = {"arg": (1, 1), "find": (1, 1), "env": (1, 1), "anon": (1, 1)}
SUBSTITUTION_ARITY.update({"optenv": (1, 99), "dirname": (0, 0)})
EVAL_FUNCTIONS = ("arg", "find", "env", "optenv", "dirname", "anon")
_XACRO = re.compile(r"^/xacro(\.py)?(?=\s)")
_MODEL_FILE = re.compile(r"([A-Za-z0-9_\-]+)\.(?:urdf\.xacro|xacro|urdf)\b")

TAG_ATTRIBUTES: dict[str, tuple[str, ...]] = {
    "launch": ("deprecated",),
    "arg": ("name", "default", "value", "doc"),
    "param": ("name", "value", "type", "textfile", "binfile", "command"),
    "rosparam": ("command", "file", "param", "ns", "subst_value"),
    "node": (
        "pkg",
        "type",
        "name",
        "args",
        "ns",
        "respawn",
        "respawn_delay",
        "required",
        "output",
        "cwd",
        "launch-prefix",
        "clear_params",
        "machine",
    ),
    "include": ("file", "ns", "clear_params", "pass_all_args"),
    "group": ("ns", "clear_params"),
    "remap": ("from", "to"),
    "env": ("name", "value"),
    "master": ("auto",),
    "test": (
        "test-name",
        "pkg",
        "type",
        "name",
        "args",
        "ns",
        "clear_params",
        "cwd",
        "launch-prefix",
        "retry",
        "time-limit",
    ),
}


@dataclass
class _ArgInfo:
    default: Value | None
    constant: bool


@dataclass
class _Scope:
    """What reading knows at one place of the file: visible args and the static namespace."""

    ns: str | None  # absolute, None when a namespace above uses substitutions
    args: dict[str, _ArgInfo]
    own: set[str] = field(default_factory=set)
    is_ns: bool = False
    is_root: bool = False

    def child(self, ns: str | None, has_ns: bool) -> _Scope:
        if not has_ns:
            child_ns = self.ns
        elif ns is None or self.ns is None:
            child_ns = None
        elif ns.startswith("/"):
            child_ns = "/" + ns.strip("/")
        else:
            child_ns = self.ns.rstrip("/") + "/" + ns.strip("/")
        return _Scope(child_ns, dict(self.args), is_ns=has_ns)


@dataclass
class _Desc:
    """A global parameter the ROS 2 nodes that read it take as their own parameter."""

    kind: str  # "robot_description" or "use_gui"
    value: PValue
    origin: str
    own: Cond | None
    model: str | None = None  # the model file's stem, for the simulator's entity name


@dataclass
class _Pending:
    """A global parameter on its way to the scope it belongs to (ROS 1 sets them first)."""

    item: SetParam | _Desc
    target: str  # "ns": the nearest <group ns> or the file; "root": the file
    refs: frozenset[str]
    conds: tuple[Cond, ...] = ()


@dataclass
class _Consumer:
    """A node that takes a global parameter as its own in ROS 2 (robot_state_publisher ...)."""

    node: NodeItem
    kind: str
    conds: tuple[Cond, ...] = ()


@dataclass
class _Out:
    """A scope read: declarations first, then its global parameters, then the rest in order."""

    decls: list[Item] = field(default_factory=list)
    params: list[Item] = field(default_factory=list)
    body: list[Item] = field(default_factory=list)
    pending: list[_Pending] = field(default_factory=list)
    consumers: list[_Consumer] = field(default_factory=list)

    def items(self) -> list[Item]:
        return [*self.decls, *self.params, *self.body]


class _Reader:
    """Reads one roslaunch file into the model."""

    def __init__(self, path: str) -> None:
        self.path = os.path.abspath(path)
        self._index: Any = None
        self.descriptions: list[_Desc] = []
        self.arbotix: list[tuple[NodeItem, ProcessItem, NodeItem, str]] = []
        self.jsp_nodes: list[NodeItem] = []
        # warnings for the nodes a robot_description / use_gui global reaches, by its origin
        self.desc_notes: dict[str, list[str]] = {}

    # --- helpers ------------------------------------------------------------------------------

    def origin(self, el: Element) -> str:
        return f"{self.path}:{el.line}"

    def error(self, el: Element, message: str) -> LaunchFileError:
        return LaunchFileError(message, where=self.origin(el), what=f"<{el.tag}>")

    @property
    def index(self) -> Any:
        if self._index is None:
            from mlaunch.ros import packages

            self._index = packages.index(launch_files=[self.path])
        return self._index

    def check_attributes(self, el: Element, out: _Out) -> None:
        """roslaunch warns about attributes it does not know, and so do we."""
        known = (*TAG_ATTRIBUTES.get(el.tag, ()), "if", "unless")
        for name in el.attrs:
            if name not in known:
                out.body.append(
                    Warn(
                        origin=self.origin(el),
                        message=f"unknown attribute {name!r} of <{el.tag}> is ignored"
                        f" (as roslaunch does); valid: {', '.join(known)}",
                    )
                )

    def attr(self, el: Element, name: str, scope: _Scope, required: bool = False) -> Value | None:
        raw = el.attrs.get(name)
        if raw is None:
            if required:
                raise self.error(el, f"missing required attribute {name!r}")
            return None
        return self.value(raw, el, name, scope)

    def literal(self, el: Element, name: str, scope: _Scope, required: bool = False) -> str | None:
        """An attribute that must be known when the file is read (no $(arg))."""
        value = self.attr(el, name, scope, required)
        if value is None:
            return None
        found = static_text(value)
        if found is None:
            raise self.error(
                el, f"attribute {name!r} must be known when the file is read: {el.attrs[name]!r}"
            )
        return found

    def flag(self, el: Element, name: str, scope: _Scope) -> bool | Value | None:
        value = self.attr(el, name, scope)
        if value is None:
            return None
        found = static_text(value)
        if found is None:
            return value
        try:
            return bool(convert_value(found, "bool"))
        except ValueError:
            raise self.error(el, f"attribute {name!r} is {found!r}, expected true or false")

    def condition(self, el: Element, scope: _Scope) -> Cond | None:
        when = self.attr(el, "if", scope)
        unless = self.attr(el, "unless", scope)
        if when is not None and unless is not None:
            raise self.error(el, "cannot set both 'if' and 'unless' on the same tag")
        chosen = when if when is not None else unless
        if chosen is None:
            return None
        found = static_text(chosen)
        if found is not None and found.strip().lower() not in ("true", "false", "1", "0"):
            which = "if" if when is not None else "unless"
            raise self.error(el, f"{which}={found!r} is not a boolean (true, false, 1, 0)")
        return Cond(chosen, unless=when is None)

    # --- values -------------------------------------------------------------------------------

    def value(self, raw: str, el: Element, attr: str, scope: _Scope) -> Value:
        """An attribute's text with roslaunch's ``$(...)`` args parsed (no nesting, as there)."""
        if raw.startswith("$(eval ") and raw.endswith(")"):
            return (self.eval(raw[7:-1], el, scope),)
        parts: list[Part] = []
        i = 0
        while True:
            j = raw.find("$(", i)
            if j < 0:
                parts.append(raw[i:])
                break
            k = raw.find(")", j)
            if k < 0:
                raise self.error(el, f"attribute {attr!r}: '$(' is not closed in {raw!r}")
            body = raw[j + 2 : k]
            if "$" in body or "(" in body:
                raise self.error(el, f"attribute {attr!r}: substitution args cannot nest: {raw!r}")
            parts.append(raw[i:j])
            parts.append(self.substitution(body, el, attr, raw, scope))
            i = k + 1
        return _rewrite_xacro(_merge(parts))

    def substitution(self, body: str, el: Element, attr: str, raw: str, scope: _Scope) -> Ref:
        words = [w for w in body.split(" ") if w]
        if not words:
            raise self.error(el, f"attribute {attr!r}: empty substitution '$()' in {raw!r}")
        command, args = words[0], words[1:]
        if command == "eval":
            raise self.error(
                el, f"attribute {attr!r}: $(eval ...) must be the whole attribute value: {raw!r}"
            )
        arity = SUBSTITUTION_ARITY.get(command)
        if arity is None:
            raise self.error(
                el,
                f"attribute {attr!r}: unknown substitution $({command}) in {raw!r}; valid:"
                f" {', '.join(sorted([*SUBSTITUTION_ARITY, 'eval']))}",
            )
        if not arity[0] <= len(args) <= arity[1]:
            raise self.error(
                el, f"attribute {attr!r}: $({command}) takes {arity[0]} argument(s): {raw!r}"
            )
        if command == "arg":
            self.check_arg(args[0], el, scope)
            return ArgRef(args[0])
        if command == "find":
            return FindRef(args[0])
        if command == "env":
            return EnvRef(args[0])
        if command == "optenv":
            return EnvRef(args[0], " ".join(args[1:]))
        if command == "anon":
            return AnonRef(args[0])
        return DirnameRef()

    def check_arg(self, name: str, el: Element, scope: _Scope) -> None:
        if name not in scope.args:
            raise self.error(
                el,
                f"arg {name!r} is not defined (declare it with <arg name={name!r} .../> before"
                " it is used)",
            )

    def eval(self, expression: str, el: Element, scope: _Scope) -> EvalRef:
        """``$(eval ...)``, checked now: Python syntax, no ``__``, every name known."""
        if "__" in expression:
            raise self.error(el, "$(eval ...) may not contain double underscore expressions")
        try:
            tree = ast.parse(expression.strip(), mode="eval")
        except SyntaxError as e:
            raise self.error(el, f"$(eval {expression}): Python syntax error: {e.msg}")
        return EvalRef(expression, _EvalCutter(self, el, scope, expression.strip()).cut(tree))

    def arg_kind(self, name: str, scope: _Scope) -> str:
        """How a converted $(eval) writes the argument: by the type of its default."""
        info = scope.args.get(name)
        found = static_text(info.default) if info is not None else None
        if found is None:
            return "str"
        value = convert_value(found.strip(), "auto")
        if isinstance(value, bool):
            return "bool"
        return "raw" if isinstance(value, (int, float)) else "str"

    def resolve_static(self, value: Value, el: Element) -> str | None:
        """A path known when the file is read: text, $(find) and $(dirname) only."""
        try:
            return resolve_static(value, self.path, self.index)
        except MlaunchError as e:
            e.where = e.where or self.origin(el)
            raise

    # --- the file -----------------------------------------------------------------------------

    def read(self) -> list[Item]:
        root = parse_xml(self.path)
        if root.tag != "launch":
            raise self.error(root, f"the root element must be <launch>, not <{root.tag}>")
        scope = _Scope("/", {}, is_ns=True, is_root=True)
        out = _Out()
        self.check_attributes(root, out)
        reason = root.attrs.get("deprecated")
        if reason is not None:
            out.decls.append(
                Warn(origin=self.origin(root), message=f"this launch file is deprecated: {reason}")
            )
        self.scope(root.children, scope, out)
        self.land(out, scope)
        for consumer in out.consumers:
            if consumer.kind == "robot_description":
                consumer.node.warnings.append(
                    "robot_state_publisher gets no robot_description: in ROS 1 it read the global"
                    " parameter (set in another file?); in ROS 2 it must be the node's own"
                    " parameter"
                )
        self.finish_arbotix()
        self.finish_jsp()
        items = out.items()
        _lower(items)
        return items

    def scope(self, elements: list[Element], scope: _Scope, out: _Out) -> None:
        for el in elements:
            handler = getattr(self, "tag_" + el.tag.replace("-", "_"), None)
            if handler is None:
                out.body.append(
                    Warn(
                        origin=self.origin(el),
                        message=f"unrecognized tag <{el.tag}> is ignored (as roslaunch does)",
                    )
                )
                continue
            self.check_attributes(el, out)
            handler(el, scope, out)

    def land(self, out: _Out, scope: _Scope) -> None:
        """Place the pending global parameters that belong to this scope; keep the others."""
        keep: list[_Pending] = []
        for pending in out.pending:
            here = (pending.target == "ns" and scope.is_ns) or scope.is_root
            uses_own = bool(pending.refs & scope.own)
            if not here and not uses_own:
                keep.append(pending)
                continue
            if uses_own and not here:
                self.warn_scope(pending)
            if isinstance(pending.item, SetParam):
                out.params.append(_wrap(pending.item, pending.conds))
            else:
                self.bind(pending, out)
        out.pending = keep

    def warn_scope(self, pending: _Pending) -> None:
        item = pending.item
        what = "robot_description" if isinstance(item, _Desc) else describe_value(item.name)
        message = (
            f"global parameter {what} reads an <arg> of its <group>, so it stays in that group:"
            " in ROS 2 only the nodes of the group get it"
        )
        if isinstance(item, _Desc):
            self.desc_notes.setdefault(item.origin, []).append(message)
        else:
            item.warnings.append(message)

    def bind(self, pending: _Pending, out: _Out) -> None:
        """Give a robot_description / use_gui global to the nodes of this scope that read it."""
        desc = pending.item
        assert isinstance(desc, _Desc)
        takers = [c for c in out.consumers if c.kind == desc.kind]
        conds = set(pending.conds) | ({desc.own} if desc.own else set())
        for consumer in takers:
            node = consumer.node
            node_conds = set(consumer.conds) | ({node.condition} if node.condition else set())
            rel = _rel(desc.origin)
            if desc.kind == "robot_description":
                node.parameters.insert(0, (text("robot_description"), desc.value))
                where = os.path.basename(desc.origin)
                node.notes.append(f"robot_description: the global parameter of {where}")
            else:
                node.gui = desc.value
            if not conds <= node_conds:
                node.warnings.append(
                    f"the global {desc.kind} of {rel} is set only under a condition this node"
                    f" does not share; in ROS 2 the node gets it whenever it runs"
                )
            node.warnings.extend(self.desc_notes.get(desc.origin, []))
        out.consumers = [c for c in out.consumers if c.kind != desc.kind]
        if takers:
            return
        if desc.kind == "use_gui":  # no joint_state_publisher here: an ordinary global
            item = SetParam(
                origin=desc.origin, condition=desc.own, name=text("use_gui"), value=desc.value
            )
            out.params.append(_wrap(item, pending.conds))
            return
        out.params.append(
            Warn(
                origin=desc.origin,
                condition=desc.own,
                message="robot_description is set, but no robot_state_publisher of this file's"
                " scope takes it: ROS 2 has no parameter server, so it reaches no node (give it"
                " to the node that needs it as a parameter)",
            )
        )

    def pass_up(self, inner: _Out, out: _Out, cond: Cond | None) -> None:
        """What a child scope leaves for its parent, under the child's condition."""
        extra = (cond,) if cond is not None else ()
        for pending in inner.pending:
            pending.conds = (*extra, *pending.conds)
            out.pending.append(pending)
        for consumer in inner.consumers:
            consumer.conds = (*extra, *consumer.conds)
            out.consumers.append(consumer)

    # --- tags ---------------------------------------------------------------------------------

    def tag_arg(self, el: Element, scope: _Scope, out: _Out) -> None:
        name = self.literal(el, "name", scope, required=True)
        assert name is not None
        default = self.attr(el, "default", scope)
        value = self.attr(el, "value", scope)
        if default is not None and value is not None:
            raise self.error(el, "<arg> tag must have one and only one of value/default")
        cond = self.condition(el, scope)
        known = scope.args.get(name)
        if known is not None and cond is None and not known.constant and name in scope.own:
            raise self.error(el, f"arg {name!r} has already been declared")
        doc = el.attrs.get("doc")
        item: Item
        if value is not None:
            item = SetArg(origin=self.origin(el), condition=cond, name=name, value=value)
        else:
            item = DeclareArg(
                origin=self.origin(el), condition=cond, name=name, default=default, doc=doc
            )
        scope.args[name] = _ArgInfo(value if value is not None else default, value is not None)
        scope.own.add(name)
        out.decls.append(item)

    def tag_param(self, el: Element, scope: _Scope, out: _Out) -> None:
        self.global_params(self.param_entries(el, scope), el, scope, out)

    def param_entries(self, el: Element, scope: _Scope) -> list[tuple[Value, PValue]]:
        """The (name, value) pairs one <param> sets (a yaml dict sets several)."""
        name = self.attr(el, "name", scope, required=True)
        assert name is not None
        given = [k for k in ("value", "textfile", "binfile", "command") if k in el.attrs]
        if len(given) != 1:
            raise self.error(
                el,
                "<param> needs exactly one of value, textfile, binfile, command"
                + (f" (got {', '.join(given)})" if given else ""),
            )
        type_name = (self.literal(el, "type", scope) or "auto").lower()
        if type_name not in PARAM_TYPES:
            raise self.error(
                el, f"type={type_name!r} is not a param type; valid: {', '.join(PARAM_TYPES)}"
            )
        source = given[0]
        raw = self.attr(el, source, scope, required=True)
        assert raw is not None
        if source == "binfile":
            raise _Skip(
                "<param binfile> (binary data, an XML-RPC Base64 value) has no ROS 2 parameter"
                " type: the parameter is not set"
            )
        if source == "textfile":
            return [(name, PValue(dynamic=(FileRef(raw),), vtype=str))]
        if source == "command":
            vtype = None if type_name == "yaml" else _VTYPES[type_name] or str
            return [(name, PValue(dynamic=(CommandRef(raw),), vtype=vtype))]
        found = static_text(raw)
        if found is None:
            return [(name, PValue(dynamic=raw, vtype=_VTYPES[type_name]))]
        try:
            literal = convert_value(found.strip(), type_name)
        except (ValueError, yaml.YAMLError) as e:
            raise self.error(el, f"param value {found!r} is not of type {type_name}: {e}")
        return self.flatten(name, literal, el)

    def flatten(self, name: Value, value: Any, el: Element) -> list[tuple[Value, PValue]]:
        """A YAML value as ROS 2 parameters: dicts become dotted names, lists stay uniform."""
        if isinstance(value, dict):
            out: list[tuple[Value, PValue]] = []
            for key, inner in value.items():
                out += self.flatten((*name, "/", str(key)), inner, el)
            return out
        problem = _ros2_problem(value)
        if problem is not None:
            raise _Skip(f"parameter {describe_value(name)}: {problem}; it is not set")
        if isinstance(value, (list, tuple)) and any(isinstance(v, float) for v in value):
            value = [float(v) for v in value]
        elif not isinstance(value, (bool, int, float, str, list)):
            value = str(value)  # dates and the like: roslaunch kept them as text-ish values
        return [(name, PValue(literal=list(value) if isinstance(value, tuple) else value))]

    def global_params(
        self, entries: list[tuple[Value, PValue]], el: Element, scope: _Scope, out: _Out
    ) -> None:
        cond = self.condition(el, scope)
        for name, value in entries:
            self.global_param(name, value, cond, el, scope, out)

    def global_param(
        self, name: Value, value: PValue, cond: Cond | None, el: Element, scope: _Scope, out: _Out
    ) -> None:
        """A parameter outside any node: where ROS 2 puts it depends on its name."""
        origin = self.origin(el)
        refs = frozenset(arg_names(name) | arg_names(value) | arg_names(cond))
        plain = static_text(name)
        target = "ns"
        if plain is not None:
            if plain.startswith("~"):
                raise self.error(el, f"private parameter {plain!r} outside a <node>")
            if plain.startswith("/"):
                inside = scope.ns is not None and scope.ns != "/"
                if inside and plain.startswith(scope.ns.rstrip("/") + "/"):  # type: ignore[union-attr]
                    plain = plain[len(scope.ns) + 1 :]  # type: ignore[arg-type]
                else:
                    target, plain = "root", plain.lstrip("/")
            dotted = _dotted(plain)
            if dotted in ("robot_description", "use_gui"):
                desc = _Desc(dotted, value, origin, cond, model=self.model_name(value, scope))
                self.descriptions.append(desc)
                out.pending.append(_Pending(desc, target, refs))
                return
            name = text(dotted)
        else:
            name = tuple(_dotted(p) if isinstance(p, str) else p for p in name)
        item = SetParam(origin=origin, condition=cond, name=name, value=value)
        out.pending.append(_Pending(item, target, refs))

    def model_name(self, value: PValue, scope: _Scope) -> str | None:
        """The robot model's file stem in a robot_description (following one $(arg))."""
        parts: list[Part] = list(value.dynamic or ())
        while parts:
            part = parts.pop(0)
            if isinstance(part, CommandRef):
                parts = [*part.command, *parts]
            elif isinstance(part, ArgRef):
                info = scope.args.get(part.name)
                if info is not None and info.default is not None:
                    parts = [*info.default, *parts]
            elif isinstance(part, str):
                found = _MODEL_FILE.findall(part)
                if found:
                    return str(found[-1])
        return None

    def tag_rosparam(self, el: Element, scope: _Scope, out: _Out) -> None:
        try:
            entries = self.rosparam_entries(el, scope)
        except _Skip as skip:
            out.body.append(Warn(origin=self.origin(el), message=skip.message))
            return
        if entries:
            self.global_params(entries, el, scope, out)

    def rosparam_entries(self, el: Element, scope: _Scope) -> list[tuple[Value, PValue]]:
        command = self.literal(el, "command", scope) or "load"
        if command in ("dump", "delete"):
            raise _Skip(
                f"<rosparam command={command!r}> is skipped: ROS 2 has no parameter server to"
                f" {command} from"
            )
        if command != "load":
            raise self.error(el, f"command={command!r} is not valid; valid: load, dump, delete")
        subst = self.flag(el, "subst_value", scope)
        if not isinstance(subst, (bool, type(None))):
            raise self.error(el, "subst_value must be known when the file is read")
        data = self.rosparam_text(el, scope)
        try:
            loaded = yaml.load(data, Loader=RosparamLoader)
        except (yaml.YAMLError, ValueError) as e:
            raise self.error(el, f"rosparam YAML is invalid: {e}")
        param = self.attr(el, "param", scope)
        if param is not None:
            loaded = {static_text(param) or "": loaded} if static_text(param) else loaded
            if static_text(param) is None:
                raise self.error(el, "param must be known when the file is read")
        if loaded is None:
            return []
        if not isinstance(loaded, dict):
            raise self.error(el, "'param' attribute must be set for non-dictionary values")
        ns = self.literal(el, "ns", scope)
        prefix: Value = text(ns) if ns else ()
        entries: list[tuple[Value, PValue]] = []
        for key, value in loaded.items():
            name: Value = (*prefix, "/", str(key)) if prefix else text(str(key))
            for entry in self.flatten(name, value, el):
                entries.append(self.substituted(entry, el, scope) if subst else entry)
        return entries

    def rosparam_text(self, el: Element, scope: _Scope) -> str:
        path_value = self.attr(el, "file", scope)
        if path_value is None:
            return "".join(el.text)
        path = self.resolve_static(path_value, el)
        if path is None:
            raise _Skip(
                f"rosparam file {el.attrs['file']!r} depends on launch arguments: mlaunch reads"
                " ROS 1 parameter files when it loads the launch file (ROS 2 nodes cannot read"
                " them), so give a fixed path ($(find pkg)/...); not loaded"
            )
        try:
            with open(path, encoding="utf-8") as f:
                return f.read()
        except OSError as e:
            raise self.error(el, f"cannot read rosparam file {path!r}: {e.strerror}")

    def substituted(
        self, entry: tuple[Value, PValue], el: Element, scope: _Scope
    ) -> tuple[Value, PValue]:
        """subst_value: text values with $(...) are performed, then typed by YAML."""
        name, value = entry
        if isinstance(value.literal, str) and "$(" in value.literal:
            return name, PValue(dynamic=self.value(value.literal, el, "rosparam", scope))
        return entry

    def tag_remap(self, el: Element, scope: _Scope, out: _Out) -> None:
        src = self.attr(el, "from", scope, required=True)
        dst = self.attr(el, "to", scope, required=True)
        assert src is not None and dst is not None
        cond = self.condition(el, scope)
        out.body.append(SetRemap(origin=self.origin(el), condition=cond, src=src, dst=dst))

    def tag_env(self, el: Element, scope: _Scope, out: _Out) -> None:
        name = self.attr(el, "name", scope, required=True)
        value = self.attr(el, "value", scope, required=True)
        assert name is not None and value is not None
        cond = self.condition(el, scope)
        out.body.append(SetEnv(origin=self.origin(el), condition=cond, name=name, value=value))

    def tag_group(self, el: Element, scope: _Scope, out: _Out) -> None:
        cond = self.condition(el, scope)
        ns = self.attr(el, "ns", scope)
        inner_scope = scope.child(static_text(ns) if ns else None, ns is not None)
        inner = _Out()
        self.scope(el.children, inner_scope, inner)
        self.land(inner, inner_scope)
        group = Group(origin=self.origin(el), condition=cond, items=inner.items(), namespace=ns)
        if "clear_params" in el.attrs:
            group.warnings.append(_CLEAR_PARAMS)
        if group.items:
            out.body.append(group)
        elif group.warnings:  # nothing left in it (its parameters moved out): only the warning
            out.body.append(Warn(origin=group.origin, condition=cond, message=_CLEAR_PARAMS))
        self.pass_up(inner, out, cond)

    def tag_include(self, el: Element, scope: _Scope, out: _Out) -> None:
        path = self.attr(el, "file", scope, required=True)
        assert path is not None
        cond = self.condition(el, scope)
        ns = self.attr(el, "ns", scope)
        arguments: list[tuple[str, Value]] = []
        envs: list[Item] = []
        notes: list[str] = []
        for child in el.children:
            if child.tag == "arg":
                self.check_attributes(child, out)
                if self.condition(child, scope) is not None:
                    notes.append(
                        f"<arg> at line {child.line}: if/unless on an <include>'s <arg> is not"
                        " supported by ROS 2 launch arguments: it is always passed"
                    )
                name = self.literal(child, "name", scope, required=True)
                value = self.attr(child, "value", scope) or self.attr(child, "default", scope)
                if value is None:
                    raise self.error(child, f"<arg name={name!r}> of an <include> needs a value")
                assert name is not None
                arguments.append((name, value))
            elif child.tag == "env":
                self.check_attributes(child, out)
                self.tag_env(child, scope, _collect := _Out())
                envs += _collect.body
            else:
                raise self.error(child, f"<{child.tag}> is not valid inside <include>")
        include = Include(origin=self.origin(el), path=path, arguments=arguments, warnings=notes)
        if "clear_params" in el.attrs:
            include.warnings.append(_CLEAR_PARAMS)
        if ns is None and not envs:
            include.condition = cond
            out.body.append(include)
            return
        group = Group(origin=self.origin(el), condition=cond, items=[*envs, include])
        group.namespace = ns
        out.body.append(group)

    def tag_test(self, el: Element, scope: _Scope, out: _Out) -> None:
        name = el.attrs.get("test-name", el.attrs.get("type", "?"))
        out.body.append(
            Warn(
                origin=self.origin(el),
                message=f"rostest <test test-name={name!r}> is skipped: it runs under rostest,"
                " not a launch (ROS 2: launch_testing)",
            )
        )

    def tag_machine(self, el: Element, scope: _Scope, out: _Out) -> None:
        raise self.error(
            el,
            "<machine> is not supported: mlaunch starts every node on this computer (ROS 1's"
            " remote machines over SSH have no ROS 2 launch equivalent; run one launch per"
            " machine)",
        )

    def tag_master(self, el: Element, scope: _Scope, out: _Out) -> None:
        out.body.append(
            Warn(origin=self.origin(el), message="<master> is ignored: ROS 2 has no master")
        )

    # --- nodes --------------------------------------------------------------------------------

    def tag_node(self, el: Element, scope: _Scope, out: _Out) -> None:
        if "machine" in el.attrs:
            raise self.error(
                el,
                f"machine={el.attrs['machine']!r} is not supported: mlaunch starts every node on"
                " this computer",
            )
        cond = self.condition(el, scope)
        node = NodeItem(
            origin=self.origin(el),
            condition=cond,
            package=self.attr(el, "pkg", scope, required=True) or (),
            executable=self.attr(el, "type", scope, required=True) or (),
            name=self.attr(el, "name", scope, required=True),
            namespace=self.attr(el, "ns", scope),
            output=self.output(el, scope),
            prefix=self.attr(el, "launch-prefix", scope),
        )
        args = self.attr(el, "args", scope)
        node.arguments = split_arguments(args) if args is not None else []
        self.process_attributes(node, el, scope)
        self.node_children(node, el, scope, out)
        for attr_name, why in (("cwd", _CWD), ("clear_params", _CLEAR_PARAMS)):
            if attr_name in el.attrs:
                node.warnings.append(why.format(value=el.attrs[attr_name]))
        out.body.extend(self.map_node(node, el, out))

    def output(self, el: Element, scope: _Scope) -> Value | None:
        value = self.attr(el, "output", scope)
        found = static_text(value)
        if found is not None and found not in ("log", "screen"):
            raise self.error(el, f"output={found!r} is not valid; valid: log, screen")
        return value

    def process_attributes(self, node: Process, el: Element, scope: _Scope) -> None:
        respawn = self.flag(el, "respawn", scope)
        required = self.flag(el, "required", scope)
        if respawn is True and required is True:
            raise self.error(el, "respawn and required cannot both be set to true")
        node.respawn = False if respawn is None else respawn
        node.required = False if required is None else required
        delay = self.attr(el, "respawn_delay", scope)
        found = static_text(delay)
        if found is not None:
            try:
                node.respawn_delay = float(found)
            except ValueError:
                raise self.error(el, f"respawn_delay={found!r} is not a number of seconds")
        else:
            node.respawn_delay = delay

    def node_children(self, node: NodeItem, el: Element, scope: _Scope, out: _Out) -> None:
        for child in el.children:
            if child.tag not in ("param", "rosparam", "remap", "env"):
                out.body.append(
                    Warn(
                        origin=self.origin(child),
                        message=f"<{child.tag}> is not valid inside <node> and is ignored (as"
                        " roslaunch does); valid: param, rosparam, remap, env",
                    )
                )
                continue
            self.check_attributes(child, out)
            if self.condition(child, scope) is not None:
                node.warnings.append(
                    f"<{child.tag}> at line {child.line}: if/unless inside a node is not"
                    " supported by ROS 2 node parameters: it always applies"
                )
            try:
                self.node_child(node, child, scope, out)
            except _Skip as skip:
                node.warnings.append(f"<{child.tag}> at line {child.line}: {skip.message}")

    def node_child(self, node: NodeItem, child: Element, scope: _Scope, out: _Out) -> None:
        if child.tag == "remap":
            src = self.attr(child, "from", scope, required=True)
            dst = self.attr(child, "to", scope, required=True)
            assert src is not None and dst is not None
            node.remappings.append((src, dst))
        elif child.tag == "env":
            env_name = self.attr(child, "name", scope, required=True)
            env_value = self.attr(child, "value", scope, required=True)
            assert env_name is not None and env_value is not None
            node.env.append((env_name, env_value))
        else:
            entries = (
                self.param_entries(child, scope)
                if child.tag == "param"
                else self.rosparam_entries(child, scope)
            )
            for name, value in entries:
                plain = static_text(name)
                if plain is not None and plain.startswith("/"):
                    self.global_param(name, value, None, child, scope, out)
                    continue
                if plain is not None:
                    name = text(_dotted(plain.lstrip("~")))
                node.parameters.append((name, value))

    def map_node(self, node: NodeItem, el: Element, out: _Out) -> list[Item]:
        """Known ROS 1 packages and programs as their ROS 2 counterparts."""
        key = (static_text(node.package), static_text(node.executable))
        if key[0] == "robot_state_publisher" and key[1] in ("state_publisher", key[0]):
            return self.map_rsp(node, out)
        if key in (("tf", "static_transform_publisher"), ("tf2_ros", "static_transform_publisher")):
            return self.map_static_tf(node, key[0] == "tf")
        if key == ("rviz", "rviz"):
            return self.map_rviz(node, el)
        if key == ("joint_state_publisher", "joint_state_publisher"):
            return self.map_jsp(node, out)
        if key == ("arbotix_python", "arbotix_driver"):
            return self.map_arbotix(node)
        return [node]

    def map_rsp(self, node: NodeItem, out: _Out) -> list[Item]:
        if static_text(node.executable) == "state_publisher":
            node.notes.append(
                "ROS 1 robot_state_publisher/state_publisher is robot_state_publisher in ROS 2"
            )
            node.executable = text("robot_state_publisher")
        kept: Params = []
        for name, value in node.parameters:
            if static_text(name) in ("tf_prefix", "use_tf_static"):
                node.warnings.append(
                    f"parameter {static_text(name)} of ROS 1 robot_state_publisher does not exist"
                    " in ROS 2 (frames are never prefixed; static transforms always go to"
                    " /tf_static): dropped"
                )
                continue
            kept.append((name, value))
        node.parameters = kept
        if not any(static_text(n) == "robot_description" for n, _ in node.parameters):
            out.consumers.append(_Consumer(node, "robot_description"))
        return [node]

    def map_static_tf(self, node: NodeItem, ros1_tf: bool) -> list[Item]:
        args = node.arguments
        counts = (9, 10) if ros1_tf else (8, 9)
        node.package = text("tf2_ros")
        if len(args) not in counts:
            node.warnings.append(
                f"static_transform_publisher takes {counts[0]} or {counts[1]} arguments (x y z"
                f" yaw pitch roll | x y z qx qy qz qw, frame, child{_PERIOD if ros1_tf else ''}),"
                f" got {len(args)}: passed to tf2_ros unchanged"
            )
        else:
            node.arguments = self.static_tf_arguments(node, list(args), ros1_tf)
        program = "tf2_ros static_transform_publisher"
        if self.available("tf2_ros", "static_transform_publisher"):
            return [node]
        frames = " -> ".join(describe_value(a) for a in _frame_args(node.arguments))
        return [
            Dropped(
                origin=node.origin,
                condition=node.condition,
                warnings=[
                    f"{program} is not installed and mlaunch has no stand-in for it (tf2_msgs"
                    f" has no wheel): the static transform {frames} is not published (the node"
                    " is dropped; it runs where tf2_ros is installed)",
                    *node.warnings,
                ],
                node=node,
            )
        ]

    def static_tf_arguments(self, node: NodeItem, args: list[Value], ros1_tf: bool) -> list[Value]:
        if ros1_tf:
            period = describe_value(args.pop())
            node.warnings.append(
                f"the period ({period} ms) of ROS 1 tf static_transform_publisher is dropped:"
                " tf2_ros publishes a static transform once, latched on /tf_static"
            )
        numbers, frames = args[:-2], args[-2:]
        flags = _EULER if len(numbers) == 6 else _QUATERNION
        out: list[Value] = []
        for flag, value in zip(flags, numbers, strict=True):
            out += [text(f"--{flag}"), value]
        stripped = [_strip_slash(f) for f in frames]
        if stripped != frames:
            node.warnings.append("frame ids lose their leading '/' (tf2 rejects it)")
        out += [text("--frame-id"), stripped[0], text("--child-frame-id"), stripped[1]]
        node.notes.append(
            "ROS 1 static_transform_publisher arguments, written as tf2_ros's named options"
        )
        return out

    def available(self, package: str, executable: str) -> bool:
        """Whether a node of the package can start here: installed, or a stand-in exists."""
        from mlaunch import standins

        if self.index.installed(package) is not None:
            return True
        return standins.standin_for_package(package, executable) is not None

    def map_rviz(self, node: NodeItem, el: Element) -> list[Item]:
        node.package = text("rviz2")
        node.executable = text("rviz2")
        node.notes.append("ROS 1 rviz/rviz is rviz2/rviz2 in ROS 2")
        config = _option_value(node.arguments, ("-d", "--display-config"))
        if config is None:
            return [node]
        path = self.resolve_static(config, el)
        reason = "could not be checked when the file was read" if path is None else ""
        if path is not None:
            reason = _rviz_config_format(path)
        if reason:
            node.warnings.append(
                f"the RViz config {describe_value(config)} {reason}: rviz2 cannot load ROS 1"
                " configs (display classes rviz/... are rviz_default_plugins/... in rviz2);"
                " save a new one from rviz2"
            )
        return [node]

    def map_jsp(self, node: NodeItem, out: _Out) -> list[Item]:
        kept: Params = []
        for name, value in node.parameters:
            if static_text(name) == "use_gui":
                node.gui = value
            else:
                kept.append((name, value))
        node.parameters = kept
        if node.gui is None:
            out.consumers.append(_Consumer(node, "use_gui"))
        self.jsp_nodes.append(node)
        return [node]

    def map_arbotix(self, node: NodeItem) -> list[Item]:
        sim = ProcessItem(
            origin=node.origin,
            condition=node.condition,
            cmd=[text(a) for a in _GZSERVER],
            output=node.output or text("screen"),
            respawn=node.respawn,
            respawn_delay=node.respawn_delay,
            required=node.required,
            prefix=node.prefix,
            env=node.env,
        )
        spawn = NodeItem(
            origin=node.origin,
            condition=node.condition,
            package=text("gazebo_ros"),
            executable=text("spawn_entity.py"),
            name=None,
            namespace=node.namespace,
            output=text("screen"),
        )
        names = list(dict.fromkeys(describe_value(n).split(".")[0] for n, _ in node.parameters))
        sim_param = next((v for n, v in node.parameters if static_text(n) == "sim"), None)
        board = ""
        if sim_param is not None and sim_param.literal is False:
            board = " (sim is false: the real ArbotiX board is not driven)"
        used = f"; its parameters ({', '.join(names)}) are not used{board}" if names else board
        self.arbotix.append((node, sim, spawn, used))
        return [sim, spawn]

    def finish_arbotix(self) -> None:
        """The spawned entity is named after the robot model (known once the file is read)."""
        model = next((d.model for d in self.descriptions if d.model), None)
        for node, sim, spawn, used in self.arbotix:
            entity = model or static_text(node.name) or "robot"
            spawn.arguments = [text(a) for a in ("-topic", "robot_description", "-entity", entity)]
            sim.warnings.append(
                "arbotix_python arbotix_driver (the ArbotiX diff-drive controller) has no ROS 2"
                " package: it is replaced by a Gazebo simulator (gzserver; mlaunch's stand-in"
                " where Gazebo is not installed) that drives the robot from /cmd_vel through the"
                " diff-drive plugin of its URDF, and spawn_entity.py spawns robot_description"
                f" as {entity!r}{used}"
            )
            sim.notes.append(f"ROS 1 node {describe_value(node.name or ())!s} (arbotix_driver)")

    def finish_jsp(self) -> None:
        for node in self.jsp_nodes:
            if node.gui is None:
                continue
            if node.gui.literal is False:
                continue
            if node.gui.literal is True:
                node.executable = node.package = text("joint_state_publisher_gui")
            node.warnings.append(
                "use_gui: ROS 2's joint_state_publisher has no GUI; joint_state_publisher_gui"
                " (its own package) runs when use_gui is true"
            )


class _Skip(Exception):
    """A tag that maps to nothing in ROS 2: a warning, not an error."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class _EvalCutter:
    """Cuts an ``$(eval)`` expression at the names and calls that read launch state."""

    def __init__(self, reader: _Reader, el: Element, scope: _Scope, expression: str) -> None:
        self.reader = reader
        self.el = el
        self.scope = scope
        self.expression = expression
        lines = expression.split("\n")
        self.starts = [0]
        for line in lines[:-1]:
            self.starts.append(self.starts[-1] + len(line) + 1)
        self.lines = lines
        self.cuts: list[tuple[int, int, str | EvalArg]] = []
        self.writable = True

    def offset(self, line: int, col: int) -> int:
        raw = self.lines[line - 1].encode("utf-8")[:col]
        return self.starts[line - 1] + len(raw.decode("utf-8", "replace"))

    def span(self, node: ast.expr) -> tuple[int, int]:
        end_line = node.end_lineno or node.lineno
        end_col = node.end_col_offset or node.col_offset
        return self.offset(node.lineno, node.col_offset), self.offset(end_line, end_col)

    def cut(self, tree: ast.Expression) -> tuple[str | EvalArg, ...] | None:
        self.visit(tree.body)
        if not self.writable:
            return None
        pieces: list[str | EvalArg] = []
        at = 0
        for start, end, piece in sorted(self.cuts, key=lambda c: c[0]):
            if start > at:
                pieces.append(self.expression[at:start])
            pieces.append(piece)
            at = end
        if at < len(self.expression):
            pieces.append(self.expression[at:])
        return tuple(pieces)

    def visit(self, node: ast.AST) -> None:
        function = _called_name(node)
        if function in EVAL_FUNCTIONS and isinstance(node, ast.Call):
            self.call(node, function)
            return
        if isinstance(node, ast.Name):
            self.name(node)
            return
        for child in ast.iter_child_nodes(node):
            self.visit(child)

    def name(self, node: ast.Name) -> None:
        start, end = self.span(node)
        if node.id in self.scope.args:
            kind = self.reader.arg_kind(node.id, self.scope)
            self.cuts.append((start, end, EvalArg(ArgRef(node.id), kind)))
        elif node.id in ("true", "false"):
            self.cuts.append((start, end, node.id.capitalize()))
        elif node.id not in _EVAL_BUILTINS and node.id not in EVAL_FUNCTIONS:
            raise self.reader.error(
                self.el,
                f"$(eval {self.expression}): {node.id!r} is neither a declared arg nor a name"
                " roslaunch's eval knows",
            )

    def call(self, node: ast.Call, function: str) -> None:
        texts = [a.value for a in node.args if isinstance(a, ast.Constant)]
        if (
            len(texts) != len(node.args)
            or node.keywords
            or not all(isinstance(t, str) for t in texts)
        ):
            self.writable = False
            for child in node.args:
                self.visit(child)
            return
        args = [str(t) for t in texts]
        ref: Ref
        kind = "str"
        if function == "arg" and len(args) == 1:
            self.reader.check_arg(args[0], self.el, self.scope)
            ref, kind = ArgRef(args[0]), self.reader.arg_kind(args[0], self.scope)
        elif function == "find" and len(args) == 1:
            ref = FindRef(args[0])
        elif function == "env" and len(args) == 1:
            ref = EnvRef(args[0])
        elif function == "optenv" and len(args) in (1, 2):
            ref = EnvRef(args[0], args[1] if len(args) == 2 else "")
        elif function == "anon" and len(args) == 1:
            ref = AnonRef(args[0])
        elif function == "dirname" and not args:
            ref = DirnameRef()
        else:
            raise self.reader.error(
                self.el, f"$(eval {self.expression}): {function}() got {len(args)} argument(s)"
            )
        start, end = self.span(node)
        self.cuts.append((start, end, EvalArg(ref, kind)))


_EVAL_BUILTINS = frozenset(vars(builtins))
_PERIOD = ", period_ms"
_EULER = ("x", "y", "z", "yaw", "pitch", "roll")
_QUATERNION = ("x", "y", "z", "qx", "qy", "qz", "qw")
_GZSERVER = ("gzserver", "-s", "libgazebo_ros_init.so", "-s", "libgazebo_ros_factory.so")
_CLEAR_PARAMS = (
    "clear_params has no effect in ROS 2: there is no parameter server, a node only has the"
    " parameters this launch gives it"
)
_CWD = (
    "cwd={value!r} is not kept: ROS 2 starts nodes in the launcher's working directory"
    " (ROS 1 used ROS_HOME)"
)


def resolve_static(value: Value, path: str, index: Any = None) -> str | None:
    """A value made of text, $(find) and $(dirname) as text (None when it has other parts)."""
    out: list[str] = []
    for part in value:
        if isinstance(part, str):
            out.append(part)
        elif isinstance(part, FindRef):
            if index is None:
                from mlaunch.ros import packages

                index = packages.index(launch_files=[path])
            out.append(str(index.get(part.package).share_directory))
        elif isinstance(part, DirnameRef):
            out.append(os.path.dirname(os.path.abspath(path)))
        else:
            return None
    return "".join(out)


def _merge(parts: list[Part]) -> Value:
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


def _rewrite_xacro(value: Value) -> Value:
    """``$(find xacro)/xacro[.py] FILE`` runs xacro: the ``xacro`` program (in-process)."""
    parts = list(value)
    for i in range(len(parts) - 1):
        nxt = parts[i + 1]
        if parts[i] == FindRef("xacro") and isinstance(nxt, str) and _XACRO.match(nxt):
            parts[i] = "xacro"
            parts[i + 1] = _XACRO.sub("", nxt)
    return _merge(parts)


def _dotted(name: str) -> str:
    """A ROS 1 parameter path as a ROS 2 parameter name (``a/b`` -> ``a.b``)."""
    return ".".join(p for p in name.split("/") if p)


def _strip_slash(value: Value) -> Value:
    if value and isinstance(value[0], str) and value[0].startswith("/"):
        return _merge([value[0].lstrip("/"), *value[1:]])
    return value


def _frame_args(arguments: list[Value]) -> list[Value]:
    found = []
    for i, item in enumerate(arguments[:-1]):
        if static_text(item) in ("--frame-id", "--child-frame-id"):
            found.append(arguments[i + 1])
    return found or arguments[-3:-1]


def _option_value(arguments: list[Value], flags: tuple[str, ...]) -> Value | None:
    for i, item in enumerate(arguments[:-1]):
        if static_text(item) in flags:
            return arguments[i + 1]
    return None


def _rviz_config_format(path: str) -> str:
    """Why a config is not for rviz2 ('' when it looks like one)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            head = f.read(65536)
    except OSError as e:
        return f"cannot be read ({e.strerror})"
    if re.search(r"Class:\s*rviz/", head):
        return "is a ROS 1 RViz config (Class: rviz/...)"
    return ""


def _ros2_problem(value: Any) -> str | None:
    """Why a YAML value cannot be a ROS 2 parameter, or None."""
    if value is None:
        return "an empty (null) value has no ROS 2 parameter type"
    if isinstance(value, (list, tuple)):
        if not value:
            return "an empty list has no ROS 2 parameter type"
        kinds = {bool if isinstance(v, bool) else type(v) for v in value}
        if kinds <= {int, float} or (len(kinds) == 1 and kinds <= {bool, str}):
            return None
        if any(isinstance(v, (dict, list, tuple)) for v in value):
            return "a list of maps or lists is not a ROS 2 parameter type"
        return "a list mixing types is not a ROS 2 parameter type"
    return None


def split_arguments(value: Value) -> list[Value]:
    """An ``args`` attribute split as roslaunch's shlex.split does; substitutions stay whole."""
    args: list[Value] = []
    current: list[Part] = []
    for part in value:
        if not isinstance(part, str):
            current.append(part)
            continue
        lexer = shlex.shlex(part, posix=True, punctuation_chars=False)
        lexer.whitespace_split = True
        lexer.commenters = ""
        try:
            words = list(lexer)
        except ValueError as e:
            raise LaunchFileError(f"args: {e} in {part!r}")
        if not words:
            if part and part[0].isspace() and current:
                args.append(_merge(current))
                current = []
            continue
        glued_left = not part[0].isspace()
        glued_right = not part[-1].isspace()
        for index, word in enumerate(words):
            if index == 0 and glued_left:
                current.append(word)
            else:
                if current:
                    args.append(_merge(current))
                current = [word]
            if index == len(words) - 1 and not glued_right:
                args.append(_merge(current))
                current = []
    if current:
        args.append(_merge(current))
    return args


def _wrap(item: Item, conds: tuple[Cond, ...]) -> Item:
    """An item under the conditions of the groups it was hoisted out of (unscoped groups)."""
    for cond in reversed(conds):
        item = Group(origin=item.origin, condition=cond, items=[item], scoped=False)
    return item


def _lower(items: list[Item]) -> None:
    """joint_state_publisher with a use_gui known only when resolving: both, under conditions."""
    for i, item in enumerate(items):
        if isinstance(item, Group):
            _lower(item.items)
        elif isinstance(item, NodeItem) and item.gui is not None and item.gui.dynamic:
            items[i] = _gui_switch(item, item.gui.dynamic)


def _gui_switch(node: NodeItem, gui: Value) -> Group:
    plain = copy.copy(node)
    plain.gui, plain.warnings, plain.condition = None, [], Cond(gui, unless=True)
    with_gui = copy.copy(plain)
    plain.notes = [*node.notes, "without the GUI (use_gui false)"]
    with_gui.notes = [*node.notes, "use_gui true: the GUI is its own package in ROS 2"]
    with_gui.package = with_gui.executable = text("joint_state_publisher_gui")
    with_gui.condition = Cond(gui)
    items: list[Item] = [plain, with_gui]
    return Group(origin=node.origin, condition=node.condition, warnings=node.warnings, items=items)


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


def _rel(origin: str) -> str:
    """An origin relative to the working directory when that is shorter."""
    try:
        rel = os.path.relpath(origin)
    except ValueError:
        return origin
    return origin if rel.startswith("../../") else rel


def read(path: str) -> list[Item]:
    """The ROS 2 description (as the model) a roslaunch file maps to."""
    return _Reader(path).read()


# --- the model as mlaunch actions ----------------------------------------------------------------


def load(path: str) -> Any:
    """The LaunchDescription of the roslaunch XML file at ``path``."""
    from mlaunch.launch.actions import LaunchDescription

    description = LaunchDescription(to_actions(read(path)))
    description.origin = f"{os.path.abspath(path)}:1"
    return description


class MappingWarning(Action):
    """A warning about the ROS 1 -> ROS 2 mapping, reported where the file is resolved."""

    def __init__(self, message: str, origin: str, condition: Any = None) -> None:
        super().__init__(condition=condition)
        self.message = message
        self.origin = origin

    def execute(self, resolver: Resolver) -> None:
        resolver.warn(f"{_rel(self.origin)}: {self.message}")

    def describe_short(self) -> str:
        return f"warning: {self.message}"


class ConstantArgument(SetLaunchConfiguration):
    """roslaunch's ``<arg value=...>``: a constant the command line cannot change."""

    def __init__(self, name: str, value: Any) -> None:
        super().__init__(name, value)
        self.arg_name = name

    def execute(self, resolver: Resolver) -> None:
        given = {a.split(":=", 1)[0] for a in resolver.context.argv}
        if self.arg_name in given:
            resolver.warn(
                f"{_rel(self.origin)}: arg {self.arg_name!r} has a fixed value in the launch"
                " file; the command-line value is ignored (roslaunch refuses to override it)"
            )
        super().execute(resolver)


def to_actions(items: list[Item]) -> list[Any]:
    """The model as mlaunch's actions (the ROS 2 classes a converted file would use)."""
    out: list[Any] = []
    for item in items:
        condition = _condition(item.condition)
        # A dropped node: why it is dropped is what matters where it runs.
        messages = item.warnings[:1] if isinstance(item, Dropped) else item.warnings
        for message in messages:
            out.append(MappingWarning(message, item.origin, _condition(item.condition)))
        action = _action(item)
        if action is None:
            continue
        action.condition = condition
        action.origin = item.origin
        out.append(action)
    return out


def _action(item: Item) -> Any:
    import mlaunch.launch.actions as core
    import mlaunch.launch_ros.actions as ros

    if isinstance(item, Warn):
        return MappingWarning(item.message, item.origin, None)
    if isinstance(item, Dropped):
        return None
    if isinstance(item, DeclareArg):
        default = None if item.default is None else subs(item.default)
        return core.DeclareLaunchArgument(item.name, default_value=default, description=item.doc)
    if isinstance(item, SetArg):
        return ConstantArgument(item.name, subs(item.value))
    if isinstance(item, SetParam):
        return ros.SetParameter(name=subs(item.name), value=parameter_value(item.value))
    if isinstance(item, SetRemap):
        return ros.SetRemap(src=subs(item.src), dst=subs(item.dst))
    if isinstance(item, SetEnv):
        return core.SetEnvironmentVariable(subs(item.name), subs(item.value))
    if isinstance(item, Group):
        actions = to_actions(item.items)
        if item.namespace is not None:
            push = ros.PushROSNamespace(subs(item.namespace))
            push.origin = item.origin
            actions.insert(0, push)
        return core.GroupAction(actions, scoped=item.scoped)
    if isinstance(item, Include):
        from mlaunch.launch.launch_description_sources import AnyLaunchDescriptionSource

        source = AnyLaunchDescriptionSource(subs(item.path))
        arguments = [(name, subs(value)) for name, value in item.arguments]
        return core.IncludeLaunchDescription(source, launch_arguments=arguments)
    if isinstance(item, NodeItem):
        return ros.Node(**node_keywords(item))
    if isinstance(item, ProcessItem):
        return core.ExecuteProcess(cmd=[subs(c) for c in item.cmd], **process_keywords(item))
    raise TypeError(f"unknown item {item!r}")


def node_keywords(node: NodeItem) -> dict[str, Any]:
    kwargs = process_keywords(node)
    kwargs["package"] = subs(node.package)
    kwargs["executable"] = subs(node.executable)
    if node.name is not None:
        kwargs["name"] = subs(node.name)
    if node.namespace is not None:
        kwargs["namespace"] = subs(node.namespace)
    if node.arguments:
        kwargs["arguments"] = [subs(a) for a in node.arguments]
    if node.parameters:
        kwargs["parameters"] = [
            {_key(name): parameter_value(value) for name, value in node.parameters}
        ]
    if node.remappings:
        kwargs["remappings"] = [(subs(a), subs(b)) for a, b in node.remappings]
    return kwargs


def process_keywords(item: Process) -> dict[str, Any]:
    import mlaunch.launch.actions as core

    kwargs: dict[str, Any] = {}
    if item.output is not None:
        kwargs["output"] = subs(item.output)
    if item.respawn is not False:
        kwargs["respawn"] = item.respawn if item.respawn is True else subs(item.respawn)
    if item.respawn_delay is not None:
        delay = item.respawn_delay
        kwargs["respawn_delay"] = delay if isinstance(delay, float) else subs(delay)
    if item.required is True:
        kwargs["on_exit"] = [core.Shutdown()]
    elif item.required is not False:
        kwargs["required"] = subs(item.required)
    if item.prefix is not None:
        kwargs["prefix"] = subs(item.prefix)
    if item.env:
        kwargs["additional_env"] = {_key(k): subs(v) for k, v in item.env}
    return kwargs


def _key(value: Value) -> Any:
    """A dict key: the text, or a tuple of text and substitutions."""
    converted = subs(value)
    if len(converted) == 1 and isinstance(converted[0], str):
        return converted[0]
    return tuple(converted)


def _condition(cond: Cond | None) -> Any:
    if cond is None:
        return None
    from mlaunch.launch.conditions import IfCondition, UnlessCondition

    return (UnlessCondition if cond.unless else IfCondition)(subs(cond.value))


def parameter_value(value: PValue) -> Any:
    """A parameter value as Node(parameters=...) and SetParameter take it."""
    if value.dynamic is None:
        return value.literal
    converted = subs(value.dynamic)
    if value.vtype is None:
        return converted
    from mlaunch.launch_ros.parameter_descriptions import ParameterValue

    return ParameterValue(converted, value_type=value.vtype)


def subs(value: Value) -> list[Any]:
    """A value as ROS 2 substitutions (a list: text and substitutions concatenate)."""
    return [_substitution(p) for p in value] if value else [""]


def _substitution(part: Part) -> Any:
    import mlaunch.launch.substitutions as core

    if isinstance(part, str):
        return part
    if isinstance(part, ArgRef):
        return core.LaunchConfiguration(part.name)
    if isinstance(part, FindRef):
        from mlaunch.launch_ros.substitutions import FindPackageShare

        return FindPackageShare(part.package)
    if isinstance(part, EnvRef):
        return core.EnvironmentVariable(part.name, default_value=part.default)
    if isinstance(part, AnonRef):
        return core.AnonName(part.name)
    if isinstance(part, DirnameRef):
        return core.ThisLaunchFileDir()
    if isinstance(part, EvalRef):
        return RoslaunchEval(part.expression)
    if isinstance(part, CommandRef):
        import mlaunch.ros.xacro  # noqa: F401  (xacro runs in-process for Command)

        return core.Command(subs(part.command), on_stderr="warn")
    if isinstance(part, FileRef):
        return core.FileContent(subs(part.path))
    raise TypeError(f"unknown substitution {part!r}")


# --- roslaunch's $(eval) -----------------------------------------------------------------------


class _EvalNames(Mapping[str, Any]):
    """The names roslaunch's eval sees: functions, then args typed as roslaunch types them."""

    def __init__(self, functions: dict[str, Any], args: Mapping[str, Any]) -> None:
        self.functions = functions
        self.args = args

    def __getitem__(self, key: str) -> Any:
        if key in self.functions:
            return self.functions[key]
        value = self.args[key]
        return convert_value(value, "auto") if isinstance(value, str) else value

    def __iter__(self) -> Iterator[str]:
        return iter({**self.functions, **self.args})

    def __len__(self) -> int:
        return len({**self.functions, **self.args})


class RoslaunchEval(Substitution):
    """``$(eval expr)`` exactly as roslaunch evaluates it (args typed, find/env/... callable)."""

    def __init__(self, expression: str) -> None:
        self.expression = expression

    def perform(self, context: LaunchContext) -> str:
        configs = {k: v for k, v in context.launch_configurations.items() if isinstance(v, str)}

        def arg(name: str) -> Any:
            if name not in configs:
                raise SubstitutionFailure(f"$(eval): arg {name!r} is not set")
            return convert_value(configs[name], "auto")

        def find(package: str) -> str:
            from mlaunch.ros import packages

            return str(packages.for_context(context).get(package).share_directory)

        def env(name: str) -> str:
            if name not in context.environment:
                raise SubstitutionFailure(f"$(eval): environment variable {name!r} is not set")
            return context.environment[name]

        def optenv(name: str, default: str = "") -> str:
            return context.environment.get(name, default)

        def dirname() -> str:
            return os.path.dirname(context.current_launch_file_path or "")

        def anon(name: str) -> str:
            from mlaunch.launch.substitutions import AnonName

            return AnonName(name).perform(context)

        functions: dict[str, Any] = {"arg": arg, "find": find, "env": env, "optenv": optenv}
        functions.update({"dirname": dirname, "anon": anon, "true": True, "false": False})
        try:
            return str(eval(self.expression, {}, _EvalNames(functions, configs)))
        except MlaunchError:
            raise
        except Exception as e:
            raise SubstitutionFailure(f"$(eval {self.expression}) failed: {type(e).__name__}: {e}")

    def describe(self) -> str:
        return f"$(eval {self.expression})"


__all__ = [
    "AnonRef",
    "ArgRef",
    "CommandRef",
    "Cond",
    "DeclareArg",
    "DirnameRef",
    "Dropped",
    "EnvRef",
    "EvalArg",
    "EvalRef",
    "FileRef",
    "FindRef",
    "Group",
    "Include",
    "Item",
    "NodeItem",
    "PValue",
    "ProcessItem",
    "RoslaunchEval",
    "SetArg",
    "SetEnv",
    "SetParam",
    "SetRemap",
    "Value",
    "Warn",
    "load",
    "read",
    "to_actions",
]
