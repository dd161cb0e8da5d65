"""``mlaunch convert``: a ROS 1 roslaunch file written out as an idiomatic ROS 2 launch file.

    mlaunch convert old.launch [--to py|yaml|xml] [-o FILE]

The file is read by the roslaunch frontend (``mlaunch.ros1.roslaunch.read``), which maps it
to the ROS 2 description it becomes; this module only *writes* that description, in Python
(launch / launch_ros classes), YAML (launch_yaml) or XML (launch_xml). Because running the ROS 1
file builds the very same description, the converted file resolves to the same plan. Every
warning of the mapping is written as a comment where it applies; a node that cannot run here is
kept, commented out, with the reason.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any
from xml.sax.saxutils import escape

import yaml

from mlaunch.errors import LaunchFileError, MlaunchError, UsageError
from mlaunch.ros1 import roslaunch as r1
from mlaunch.ros1.roslaunch import (
    AnonRef,
    ArgRef,
    CommandRef,
    Cond,
    DeclareArg,
    DirnameRef,
    Dropped,
    EnvRef,
    EvalRef,
    FileRef,
    FindRef,
    Group,
    Include,
    Item,
    NodeItem,
    Part,
    ProcessItem,
    PValue,
    SetArg,
    SetEnv,
    SetParam,
    SetRemap,
    Value,
    Warn,
)

FORMATS = {"py": ".launch.py", "yaml": ".launch.yaml", "xml": ".launch.xml"}
WIDTH = 99


class ConversionError(MlaunchError):
    """Something the ROS 1 file does that the chosen ROS 2 format cannot write."""


# --- what every writer shares -------------------------------------------------------------------


@dataclass
class Source:
    """The file being converted and where the result goes (paths that depend on it)."""

    path: str
    output: str | None
    fmt: str

    @property
    def same_folder(self) -> bool:
        if self.output is None:
            return True
        return os.path.dirname(os.path.abspath(self.output)) == os.path.dirname(self.path)

    def rel(self, origin: str) -> str:
        """``file:line`` as a comment names it: the source file's name and the line."""
        path, _, line = origin.rpartition(":")
        return f"{os.path.basename(path)}:{line}"

    def dirname_value(self) -> Value:
        """``$(dirname)``: the converted file's folder when it sits beside the source."""
        if self.same_folder:
            return (DirnameRef(),)
        return (os.path.dirname(self.path),)

    def include_path(self, item: Include) -> tuple[Value, str | None]:
        """An included ROS 1 file: its converted twin when one exists beside it."""
        try:
            path = r1.resolve_static(item.path, self.path)
        except MlaunchError as e:  # a package not here: ROS 2 will look it up when launching
            return item.path, f"cannot check for a converted twin of the included file: {e}"
        last = item.path[-1] if item.path else ""
        if path is None or not path.endswith(".launch") or not isinstance(last, str):
            return item.path, None
        suffix = FORMATS[self.fmt]
        if os.path.exists(path[: -len(".launch")] + suffix):
            return (*item.path[:-1], last[: -len(".launch")] + suffix), None
        return item.path, (
            f"{os.path.basename(path)} is a ROS 1 file: mlaunch includes it as it is, ROS 2"
            f" cannot (convert it too: mlaunch convert {os.path.basename(path)} --to {self.fmt}"
            f" -o {os.path.basename(path)[: -len('.launch')]}{suffix})"
        )


def wrap(textline: str, width: int) -> list[str]:
    """A comment's words in lines of at most ``width`` characters."""
    lines: list[str] = []
    current = ""
    for word in textline.split():
        if current and len(current) + 1 + len(word) > width:
            lines.append(current)
            current = word
        else:
            current = f"{current} {word}" if current else word
    if current:
        lines.append(current)
    return lines or [""]


def comments(item: Item, source: Source) -> list[str]:
    """The comment lines before an item: where it came from, notes, then its warnings."""
    where = source.rel(item.origin)
    notes = list(getattr(item, "notes", []))
    out = [f"{where}" + (f": {notes[0]}" if notes else "")]
    out += notes[1:]
    out += [f"WARNING: {w}" for w in [*item.warnings, *format_warnings(item, source)]]
    if isinstance(item, Warn):
        out.append(f"WARNING: {item.message}")
    return out


def format_warnings(item: Item, source: Source) -> list[str]:
    """What the output format itself cannot say the way roslaunch did."""
    out: list[str] = []
    if isinstance(item, Include):
        warning = source.include_path(item)[1]
        if warning:
            out.append(warning)
    if isinstance(item, r1.Process) and item.required not in (True, False):
        out.append(
            "required depends on a launch argument: written as mlaunch's required (ROS 2 has"
            " only an unconditional on_exit shutdown)"
        )
    dynamic_type = isinstance(item, SetParam) and item.value.dynamic and item.value.vtype
    if dynamic_type and source.fmt != "py":
        out.append(
            "roslaunch forced this value's type; <set_parameter> takes no type, so ROS 2 reads"
            " it with YAML rules"
        )
    return out


def literal_text(value: Any) -> str:
    """A typed literal as launch_xml/launch_yaml text that reads back as the same type."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return yaml_float(value)
    if isinstance(value, list):
        return "[" + ", ".join(_list_item(v) for v in value) + "]"
    return str(value)


def _list_item(value: Any) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    return literal_text(value)


def yaml_float(value: float) -> str:
    """A float YAML 1.1 reads as a float (it needs a dot; ``1e-05`` alone is text)."""
    if value != value:
        return ".nan"
    if value in (float("inf"), float("-inf")):
        return ".inf" if value > 0 else "-.inf"
    found = repr(value)
    if "e" in found:
        mantissa, exponent = found.split("e")
        if "." not in mantissa:
            mantissa += ".0"
        sign = "" if exponent.startswith(("-", "+")) else "+"
        return f"{mantissa}e{sign}{exponent}"
    return found


def reads_back(value: str) -> bool:
    """Whether ROS 2's untyped param guess reads this text as the same string."""
    try:
        return yaml.safe_load(value) == value
    except yaml.YAMLError:
        return True


# --- the substitution language of launch_xml / launch_yaml ---------------------------------------

_PLAIN_ARG = re.compile(r"[^\s()'\"$\\]+")


class Templates:
    """Values as ``$(...)`` templates (what the XML and YAML formats write)."""

    def __init__(self, source: Source) -> None:
        self.source = source

    def value(self, value: Value) -> str:
        return "".join(self.part(p, quote=None) for p in value)

    def part(self, part: Part, quote: str | None) -> str:
        if isinstance(part, str):
            return _escape_text(part, quote)
        if isinstance(part, DirnameRef):
            replaced = self.source.dirname_value()
            if not isinstance(replaced[0], DirnameRef):
                return _escape_text(str(replaced[0]), quote)
        return self.substitution(part, nested=quote is not None)

    def substitution(self, part: Part, nested: bool) -> str:
        if isinstance(part, ArgRef):
            return f"$(var {self.arg(part.name, nested)})"
        if isinstance(part, FindRef):
            return f"$(find-pkg-share {self.arg(part.package, nested)})"
        if isinstance(part, EnvRef):
            if part.default is None:
                return f"$(env {self.arg(part.name, nested)})"
            return f"$(env {self.arg(part.name, nested)} {self.arg(part.default, nested)})"
        if isinstance(part, AnonRef):
            return f"$(anon {self.arg(part.name, nested)})"
        if isinstance(part, DirnameRef):
            return "$(dirname)"
        if isinstance(part, EvalRef):
            return f"$(eval {self.quoted(self.eval_parts(part), nested, 'eval')})"
        if isinstance(part, CommandRef):
            return f"$(command {self.quoted(part.command, nested, 'command')} warn)"
        if isinstance(part, FileRef):
            return f"$(file-content {self.quoted(part.path, nested, 'file-content')})"
        raise TypeError(f"unknown substitution {part!r}")

    def arg(self, word: str, nested: bool) -> str:
        """One argument of a substitution: plain, or quoted when it must be."""
        if _PLAIN_ARG.fullmatch(word):
            return word
        if nested:
            raise ConversionError(
                f"the value {word!r} needs quotes inside a quoted substitution argument, which"
                " launch_xml/launch_yaml cannot write (write the file as Python: --to py)"
            )
        return self.quoted((word,), False, "")

    def quoted(self, value: Value, nested: bool, what: str) -> str:
        if nested:
            raise ConversionError(
                f"$({what} ...) inside another substitution's quoted argument cannot be written"
                " in launch_xml/launch_yaml (write the file as Python: --to py)"
            )
        flat = "".join(p for p in value if isinstance(p, str))
        quote = '"' if "'" in flat and '"' not in flat else "'"
        return quote + "".join(self.part(p, quote) for p in value) + quote

    def eval_parts(self, part: EvalRef) -> Value:
        return eval_pieces(part)


def _escape_text(value: str, quote: str | None) -> str:
    out = value.replace("\\", "\\\\").replace("$(", "\\$(")
    if quote is not None:
        out = out.replace(quote, "\\" + quote)
    return out


def eval_pieces(part: EvalRef) -> Value:
    """A roslaunch ``$(eval)`` as a ROS 2 PythonExpression's parts.

    Arguments are inserted by the type their default had when the file was read: numbers as
    they are, text quoted, booleans compared as text (roslaunch typed them at run time).
    """
    if part.pieces is None:
        raise ConversionError(
            f"$(eval {part.expression}) calls arg/find/env/optenv/anon with computed arguments;"
            " ROS 2's PythonExpression cannot do that: rewrite it with literal arguments"
        )
    out: list[Part] = []
    for piece in part.pieces:
        if isinstance(piece, str):
            out.append(piece)
        elif piece.kind == "raw":
            out.append(piece.ref)
        elif piece.kind == "bool":
            out += ["('", piece.ref, "'.lower() in ('true', '1'))"]
        else:
            out += ["'", piece.ref, "'"]
    return r1._merge(out)


# --- Python -------------------------------------------------------------------------------------


@dataclass
class Py:
    """A Python expression to print: a call, a list, a dict, a tuple, or ready code."""

    kind: str  # "call", "list", "dict", "tuple", "code"
    name: str = ""
    # Py, (key, Py), ("#", comments to wrap) or ("#!", code lines to comment out as they are)
    items: list[Any] = field(default_factory=list)
    keywords: list[tuple[str, Py]] = field(default_factory=list)


def code(text_: str) -> Py:
    return Py("code", name=text_)


def pystr(value: str) -> Py:
    if '"' in value and "'" not in value:
        return code(repr(value))
    return code(json.dumps(value, ensure_ascii=False))


def call(callee: str, /, *args: Py, **keywords: Py | None) -> Py:
    return Py(
        "call", name=callee, items=list(args), keywords=[(k, v) for k, v in keywords.items() if v]
    )


def render(expr: Py, indent: int, used: int = 0) -> str:
    """The expression on one line when it fits (and holds no comment), else spread out.

    ``used``: what precedes it on its line after the indentation (``name=``, ``key: ``).
    """
    flat = _flat(expr)
    if flat is not None and (expr.kind == "code" or indent + used + len(flat) + 1 <= WIDTH):
        return flat
    pad = " " * (indent + 4)
    lines: list[str] = []
    if expr.kind == "call":
        lines += [pad + render(a, indent + 4) + "," for a in expr.items]
        lines += [f"{pad}{k}={render(v, indent + 4, len(k) + 1)}," for k, v in expr.keywords]
        head, tail = expr.name + "(", ")"
    else:
        head, tail = {"list": ("[", "]"), "dict": ("{", "}"), "tuple": ("(", ")")}[expr.kind]
        for item in expr.items:
            if isinstance(item, tuple) and item[0] == "#!":  # code, commented out as it is
                lines += [f"{pad}# {line}" for line in item[1]]
            elif isinstance(item, tuple) and item[0] == "#":
                for comment in item[1]:
                    lines += [f"{pad}# {line}" for line in wrap(comment, WIDTH - len(pad) - 2)]
            elif isinstance(item, tuple):
                key = render(item[0], indent + 4)
                lines.append(f"{pad}{key}: {render(item[1], indent + 4, len(key) + 2)},")
            else:
                lines.append(pad + render(item, indent + 4) + ",")
    return head + "\n" + "\n".join(lines) + "\n" + " " * indent + tail


def _flat(expr: Py) -> str | None:
    if expr.kind == "code":
        return expr.name
    parts: list[str] = []
    for item in expr.items:
        if isinstance(item, tuple) and item[0] in ("#", "#!"):
            return None
        if isinstance(item, tuple):
            key, value = _flat(item[0]), _flat(item[1])
            if key is None or value is None:
                return None
            parts.append(f"{key}: {value}")
        else:
            found = _flat(item)
            if found is None:
                return None
            parts.append(found)
    for key_name, keyword_value in expr.keywords:
        found = _flat(keyword_value)
        if found is None:
            return None
        parts.append(f"{key_name}={found}")
    inner = ", ".join(parts)
    if expr.kind == "call":
        return f"{expr.name}({inner})"
    if expr.kind == "tuple":
        return f"({inner},)" if len(parts) == 1 else f"({inner})"
    return {"list": f"[{inner}]", "dict": f"{{{inner}}}"}[expr.kind]


IMPORTS = {
    "LaunchDescription": "launch",
    "AnyLaunchDescriptionSource": "launch.launch_description_sources",
    "IfCondition": "launch.conditions",
    "UnlessCondition": "launch.conditions",
    "Node": "launch_ros.actions",
    "PushROSNamespace": "launch_ros.actions",
    "SetParameter": "launch_ros.actions",
    "SetRemap": "launch_ros.actions",
    "ParameterValue": "launch_ros.parameter_descriptions",
    "FindPackageShare": "launch_ros.substitutions",
}
for _name in (
    "DeclareLaunchArgument",
    "ExecuteProcess",
    "GroupAction",
    "IncludeLaunchDescription",
    "SetEnvironmentVariable",
    "SetLaunchConfiguration",
    "Shutdown",
):
    IMPORTS[_name] = "launch.actions"
for _name in (
    "AnonName",
    "Command",
    "EnvironmentVariable",
    "FileContent",
    "LaunchConfiguration",
    "PythonExpression",
    "ThisLaunchFileDir",
):
    IMPORTS[_name] = "launch.substitutions"


class PythonWriter:
    """The description as a ``generate_launch_description()`` of launch / launch_ros classes."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.used: set[str] = {"LaunchDescription"}

    def use(self, callee: str, /, *args: Py, **keywords: Py | None) -> Py:
        self.used.add(callee)
        return call(callee, *args, **keywords)

    def write(self, items: list[Item]) -> str:
        body = render(self.use("LaunchDescription", self.items(items)), 4, len("return "))
        header = _header(self.source, '"""', '"""')
        imports = _imports(self.used)
        return (
            f"{header}\n\n{imports}\n\n\n"
            "def generate_launch_description() -> LaunchDescription:\n"
            f"    return {body}\n"
        )

    def items(self, items: list[Item]) -> Py:
        out: list[Any] = []
        for item in items:
            out.append(("#", comments(item, self.source)))
            if isinstance(item, Dropped):
                dropped = render(self.node(item.node), 0).splitlines()
                out.append(("#", ["Where it can run:"]))
                out.append(("#!", dropped))
                continue
            action = self.action(item)
            if action is not None:
                out.append(action)
        return Py("list", items=out)

    def action(self, item: Item) -> Py | None:
        condition = self.condition(item.condition)
        if isinstance(item, Warn):
            return None
        if isinstance(item, DeclareArg):
            default = None if item.default is None else self.value(item.default)
            description = None if item.doc is None else pystr(item.doc)
            return self.use(
                "DeclareLaunchArgument",
                pystr(item.name),
                default_value=default,
                description=description,
                condition=condition,
            )
        if isinstance(item, SetArg):
            return self.use(
                "SetLaunchConfiguration",
                pystr(item.name),
                self.value(item.value),
                condition=condition,
            )
        if isinstance(item, SetParam):
            return self.use(
                "SetParameter",
                name=self.value(item.name),
                value=self.param(item.value),
                condition=condition,
            )
        if isinstance(item, SetRemap):
            return self.use(
                "SetRemap", src=self.value(item.src), dst=self.value(item.dst), condition=condition
            )
        if isinstance(item, SetEnv):
            return self.use(
                "SetEnvironmentVariable",
                self.value(item.name),
                self.value(item.value),
                condition=condition,
            )
        if isinstance(item, Group):
            return self.group(item, condition)
        if isinstance(item, Include):
            return self.include(item, condition)
        if isinstance(item, NodeItem):
            return self.node(item)
        if isinstance(item, ProcessItem):
            return self.use(
                "ExecuteProcess",
                cmd=Py("list", items=[self.value(c) for c in item.cmd]),
                **self.process(item),
            )
        raise TypeError(f"unknown item {item!r}")

    def group(self, item: Group, condition: Py | None) -> Py:
        inner = self.items(item.items)
        if item.namespace is not None:
            inner.items.insert(0, self.use("PushROSNamespace", self.value(item.namespace)))
        scoped = None if item.scoped else code("False")
        return self.use("GroupAction", inner, scoped=scoped, condition=condition)

    def include(self, item: Include, condition: Py | None) -> Py:
        path = self.source.include_path(item)[0]
        source = self.use("AnyLaunchDescriptionSource", self.value(path))
        arguments = None
        if item.arguments:
            pairs = [Py("tuple", items=[pystr(n), self.value(v)]) for n, v in item.arguments]
            arguments = Py("list", items=pairs)
        return self.use(
            "IncludeLaunchDescription", source, launch_arguments=arguments, condition=condition
        )

    def node(self, item: NodeItem) -> Py:
        keywords: dict[str, Py | None] = {
            "package": self.value(item.package),
            "executable": self.value(item.executable),
            "name": None if item.name is None else self.value(item.name),
            "namespace": None if item.namespace is None else self.value(item.namespace),
        }
        if item.arguments:
            keywords["arguments"] = Py("list", items=[self.value(a) for a in item.arguments])
        if item.parameters:
            pairs = [(self.key(n), self.param(v)) for n, v in item.parameters]
            keywords["parameters"] = Py("list", items=[Py("dict", items=pairs)])
        if item.remappings:
            keywords["remappings"] = Py(
                "list",
                items=[
                    Py("tuple", items=[self.value(a), self.value(b)]) for a, b in item.remappings
                ],
            )
        keywords.update(self.process(item))
        return self.use("Node", **keywords)

    def process(self, item: r1.Process) -> dict[str, Py | None]:
        keywords: dict[str, Py | None] = {}
        if item.output is not None:
            keywords["output"] = self.value(item.output)
        if item.respawn is not False:
            keywords["respawn"] = code("True") if item.respawn is True else self.value(item.respawn)
        if item.respawn_delay is not None:
            delay = item.respawn_delay
            keywords["respawn_delay"] = (
                code(repr(delay)) if isinstance(delay, float) else self.value(delay)
            )
        if item.required is True:
            keywords["on_exit"] = self.use("Shutdown")
        elif item.required is not False:
            keywords["required"] = self.value(item.required)
        if item.prefix is not None:
            keywords["prefix"] = self.value(item.prefix)
        if item.env:
            keywords["additional_env"] = Py(
                "dict", items=[(self.key(k), self.value(v)) for k, v in item.env]
            )
        keywords["condition"] = self.condition(item.condition)
        return keywords

    def condition(self, cond: Cond | None) -> Py | None:
        if cond is None:
            return None
        return self.use("UnlessCondition" if cond.unless else "IfCondition", self.value(cond.value))

    def param(self, value: PValue) -> Py:
        if value.dynamic is None:
            return code(pyliteral(value.literal))
        inner = self.value(value.dynamic)
        if value.vtype is None:
            return inner
        return self.use("ParameterValue", inner, value_type=code(value.vtype.__name__))

    def key(self, value: Value) -> Py:
        if len(value) == 1:
            return self.value(value)
        return Py("tuple", items=[self.part(p) for p in value])

    def value(self, value: Value) -> Py:
        parts = [self.part(p) for p in value] if value else [pystr("")]
        return parts[0] if len(parts) == 1 else Py("list", items=parts)

    def part(self, part: Part) -> Py:
        if isinstance(part, str):
            return pystr(part)
        if isinstance(part, ArgRef):
            return self.use("LaunchConfiguration", pystr(part.name))
        if isinstance(part, FindRef):
            return self.use("FindPackageShare", pystr(part.package))
        if isinstance(part, EnvRef):
            default = None if part.default is None else pystr(part.default)
            return self.use("EnvironmentVariable", pystr(part.name), default_value=default)
        if isinstance(part, AnonRef):
            return self.use("AnonName", pystr(part.name))
        if isinstance(part, DirnameRef):
            replaced = self.source.dirname_value()
            if isinstance(replaced[0], str):
                return pystr(replaced[0])
            return self.use("ThisLaunchFileDir")
        if isinstance(part, EvalRef):
            pieces = eval_pieces(part)
            return self.use("PythonExpression", Py("list", items=[self.part(p) for p in pieces]))
        if isinstance(part, CommandRef):
            return self.use("Command", self.value(part.command), on_stderr=pystr("warn"))
        if isinstance(part, FileRef):
            return self.use("FileContent", self.value(part.path))
        raise TypeError(f"unknown substitution {part!r}")


def pyliteral(value: Any) -> str:
    """A parameter literal as Python source, strings in double quotes as ruff writes them."""
    if isinstance(value, str):
        return _flat(pystr(value)) or ""
    if isinstance(value, list):
        return "[" + ", ".join(pyliteral(v) for v in value) + "]"
    return repr(value)


def _header(source: Source, opening: str, closing: str, prefix: str = "") -> str:
    name = os.path.basename(source.path)
    lines = [
        f"ROS 2 launch file converted by 'mlaunch convert' from the ROS 1 file {name}.",
        "",
        "Each action is preceded by the ROS 1 line it comes from; WARNING comments mark what",
        "ROS 2 does differently (the mapping is in mlaunch's docs/ros1.md). Running the ROS 1",
        "file with mlaunch resolves to the same plan as this file.",
    ]
    body = "\n".join(prefix + line if line else prefix.rstrip() for line in lines)
    return f"{opening}{body}\n{closing}" if opening else body


def _imports(used: set[str]) -> str:
    by_module: dict[str, list[str]] = {}
    for name in sorted(used):
        by_module.setdefault(IMPORTS[name], []).append(name)
    lines = []
    for module in sorted(by_module):
        names = ", ".join(by_module[module])
        line = f"from {module} import {names}"
        if len(line) > WIDTH:
            inner = "".join(f"    {n},\n" for n in by_module[module])
            line = f"from {module} import (\n{inner})"
        lines.append(line)
    return "\n".join(lines)


# --- XML ----------------------------------------------------------------------------------------


class XmlWriter:
    """The description as a launch_xml file."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.t = Templates(source)

    def write(self, items: list[Item]) -> str:
        header = _header(self.source, "", "", "     ")
        lines = ['<?xml version="1.0"?>', f"<!-- {header.strip()} -->", "<launch>"]
        lines += self.items(items, 1)
        lines.append("</launch>")
        return "\n".join(lines) + "\n"

    def items(self, items: list[Item], depth: int) -> list[str]:
        pad = "  " * depth
        out: list[str] = []
        for item in items:
            for comment in comments(item, self.source):
                out += _xml_comment(comment, pad)
            if isinstance(item, Dropped):
                snippet = self.element(item.node, depth)
                out += _xml_comment("Where it can run (XML comments cannot hold '--'):", pad)
                out += [f"{pad}<!-- {line.strip()} -->" for line in _xml_safe(snippet)]
                continue
            if not isinstance(item, Warn):
                out += self.element(item, depth)
        return out

    def element(self, item: Item, depth: int) -> list[str]:
        pad = "  " * depth
        attrs = self.attributes(item)
        children = self.children(item, depth + 1)
        tag = self.tag(item)
        opening = f"{pad}<{tag}" + "".join(f" {k}={_xml_attr(v)}" for k, v in attrs)
        if not children:
            return [opening + "/>"]
        return [opening + ">", *children, f"{pad}</{tag}>"]

    def tag(self, item: Item) -> str:
        names: dict[type, str] = {
            DeclareArg: "arg",
            SetArg: "let",
            SetParam: "set_parameter",
            SetRemap: "set_remap",
            SetEnv: "set_env",
            Group: "group",
            Include: "include",
            NodeItem: "node",
            ProcessItem: "executable",
        }
        return names[type(item)]

    def attributes(self, item: Item) -> list[tuple[str, str]]:
        v = self.t.value
        attrs: list[tuple[str, str]] = []
        if isinstance(item, DeclareArg):
            attrs.append(("name", item.name))
            if item.default is not None:
                attrs.append(("default", v(item.default)))
            if item.doc is not None:
                attrs.append(("description", item.doc))
        elif isinstance(item, SetArg):
            attrs += [("name", item.name), ("value", v(item.value))]
        elif isinstance(item, SetParam):
            attrs += [("name", v(item.name)), ("value", self.param_text(item.value))]
        elif isinstance(item, SetRemap):
            attrs += [("from", v(item.src)), ("to", v(item.dst))]
        elif isinstance(item, SetEnv):
            attrs += [("name", v(item.name)), ("value", v(item.value))]
        elif isinstance(item, Group):
            if not item.scoped:
                attrs.append(("scoped", "false"))
        elif isinstance(item, Include):
            attrs.append(("file", v(self.source.include_path(item)[0])))
        elif isinstance(item, NodeItem):
            attrs += [("pkg", v(item.package)), ("exec", v(item.executable))]
            if item.name is not None:
                attrs.append(("name", v(item.name)))
            if item.namespace is not None:
                attrs.append(("namespace", v(item.namespace)))
            if item.arguments:
                attrs.append(("args", self.command_line(item.arguments)))
            attrs += self.process(item)
        elif isinstance(item, ProcessItem):
            attrs.append(("cmd", self.command_line(item.cmd)))
            attrs += self.process(item)
        if item.condition is not None:
            key = "unless" if item.condition.unless else "if"
            attrs.append((key, v(item.condition.value)))
        return attrs

    def process(self, item: r1.Process) -> list[tuple[str, str]]:
        v = self.t.value
        attrs: list[tuple[str, str]] = []
        if item.output is not None:
            attrs.append(("output", v(item.output)))
        if item.respawn is not False:
            attrs.append(("respawn", "true" if item.respawn is True else v(item.respawn)))
        if item.respawn_delay is not None:
            delay = item.respawn_delay
            attrs.append(("respawn_delay", repr(delay) if isinstance(delay, float) else v(delay)))
        if item.required is True:
            attrs.append(("on_exit", "shutdown"))
        elif item.required is not False:
            attrs.append(("required", v(item.required)))
        if item.prefix is not None:
            attrs.append(("launch-prefix", v(item.prefix)))
        return attrs

    def children(self, item: Item, depth: int) -> list[str]:
        pad = "  " * depth
        v = self.t.value
        out: list[str] = []
        if isinstance(item, Group):
            if item.namespace is not None:
                out.append(f"{pad}<push_ros_namespace namespace={_xml_attr(v(item.namespace))}/>")
            out += self.items(item.items, depth)
        elif isinstance(item, Include):
            for arg_name, arg_value in item.arguments:
                out.append(
                    f"{pad}<arg" + _xml_attrs([("name", arg_name), ("value", v(arg_value))]) + "/>"
                )
        elif isinstance(item, (NodeItem, ProcessItem)):
            if isinstance(item, NodeItem):
                for param_name, param_value in item.parameters:
                    attrs = [("name", v(param_name)), *self.param_attributes(param_value)]
                    out.append(f"{pad}<param" + _xml_attrs(attrs) + "/>")
                for src, dst in item.remappings:
                    out.append(
                        f"{pad}<remap" + _xml_attrs([("from", v(src)), ("to", v(dst))]) + "/>"
                    )
            for env_name, env_value in item.env:
                out.append(
                    f"{pad}<env"
                    + _xml_attrs([("name", v(env_name)), ("value", v(env_value))])
                    + "/>"
                )
        return out

    def param_text(self, value: PValue) -> str:
        if value.dynamic is not None:
            return self.t.value(value.dynamic)
        return literal_text(value.literal)

    def param_attributes(self, value: PValue) -> list[tuple[str, str]]:
        """value (and type when ROS 2's guess would read the text as another type)."""
        found = self.param_text(value)
        attrs = [("value", found)]
        if value.dynamic is not None and value.vtype is not None:
            attrs.append(("type", _TYPE_NAMES[value.vtype]))
        elif isinstance(value.literal, str) and not reads_back(value.literal):
            attrs.append(("type", "str"))
        elif isinstance(value.literal, list) and value.literal:
            kinds = {type(x) for x in value.literal}
            if kinds == {str} and not all(reads_back(x) for x in value.literal):
                attrs.append(("type", "list_of_str"))
        return attrs

    def command_line(self, values: list[Value]) -> str:
        return " ".join(_shell_word(self.t.value(a), _needs_quotes(a)) for a in values)


_TYPE_NAMES = {str: "str", int: "int", float: "float", bool: "bool"}


def _needs_quotes(value: Value) -> bool:
    """Whether an argv item must be quoted: its text (not its substitutions) has spaces."""
    texts = [p for p in value if isinstance(p, str)]
    return not value or any(re.search(r"[\s'\"]", t) for t in texts) or texts == [""]


def _shell_word(word: str, quote: bool) -> str:
    if not quote:
        return word
    return '"' + word.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _xml_attr(value: str) -> str:
    return '"' + escape(value, {'"': "&quot;", "\n": "&#10;"}) + '"'


def _xml_attrs(attrs: list[tuple[str, str]]) -> str:
    return "".join(f" {k}={_xml_attr(v)}" for k, v in attrs)


def _xml_safe(lines: list[str]) -> list[str]:
    """Lines inside an XML comment cannot hold '--'."""
    return [line.replace("--", "- -") for line in lines]


def _xml_comment(comment: str, pad: str) -> list[str]:
    lines = wrap(comment.replace("--", "- -"), WIDTH - len(pad) - 9)
    if len(lines) == 1:
        return [f"{pad}<!-- {lines[0]} -->"]
    return [
        f"{pad}<!-- {lines[0]}",
        *(f"{pad}     {x}" for x in lines[1:-1]),
        f"{pad}     {lines[-1]} -->",
    ]


# --- YAML ---------------------------------------------------------------------------------------


class YamlWriter:
    """The description as a launch_yaml file."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.t = Templates(source)
        self.xml = XmlWriter(source)  # shares the attribute choices

    def write(self, items: list[Item]) -> str:
        header = _header(self.source, "", "", "# ")
        lines = [header, "", "launch:"]
        lines += self.items(items, 0)
        return "\n".join(lines) + "\n"

    def items(self, items: list[Item], indent: int) -> list[str]:
        pad = " " * indent
        out: list[str] = []
        for item in items:
            for comment in comments(item, self.source):
                out += [f"{pad}# {x}" for x in wrap(comment, WIDTH - indent - 2)]
            if isinstance(item, Dropped):
                out.append(f"{pad}# Where it can run:")
                out += [f"{pad}# {x}" for x in self.entity(item.node, indent)]
                continue
            if not isinstance(item, Warn):
                out += self.entity(item, indent)
        return out

    def entity(self, item: Item, indent: int) -> list[str]:
        pad = " " * indent
        tag = self.xml.tag(item)
        attrs = self.xml.attributes(item)
        lines = [f"{pad}- {tag}:"]
        inner = pad + "    "
        for key, value in attrs:
            lines.append(f"{inner}{key}: {self.scalar(key, value, item)}")
        lines += self.children(item, indent + 4)
        if len(lines) == 1:
            lines[0] += " {}"
        return lines

    def scalar(self, key: str, value: str, item: Item) -> str:
        """Attribute values are text; respawn/scoped flags and numbers keep their YAML type."""
        if key in ("respawn", "scoped") and value in ("true", "false"):
            return value
        if key == "respawn_delay" and isinstance(getattr(item, "respawn_delay", None), float):
            return value
        if key == "value" and isinstance(item, SetParam) and item.value.dynamic is None:
            return _yaml_literal(item.value.literal)
        return yaml_str(value)

    def children(self, item: Item, indent: int) -> list[str]:
        pad = " " * indent
        v = self.t.value
        out: list[str] = []
        if isinstance(item, Group):
            out.append(f"{pad}children:" + ("" if item.items or item.namespace else " []"))
            if item.namespace is not None:
                out += [
                    f"{pad}- push_ros_namespace:",
                    f"{pad}    namespace: {yaml_str(v(item.namespace))}",
                ]
            out += self.items(item.items, indent)
        elif isinstance(item, Include) and item.arguments:
            out.append(f"{pad}arg:")
            for arg_name, arg_value in item.arguments:
                out.append(f"{pad}- {_pair('name', arg_name, 'value', v(arg_value))}")
        elif isinstance(item, (NodeItem, ProcessItem)):
            if isinstance(item, NodeItem) and item.parameters:
                out.append(f"{pad}param:")
                for param_name, param_value in item.parameters:
                    out += self.param(param_name, param_value, pad)
            if isinstance(item, NodeItem) and item.remappings:
                out.append(f"{pad}remap:")
                for src, dst in item.remappings:
                    out.append(f"{pad}- {{from: {json.dumps(v(src))}, to: {json.dumps(v(dst))}}}")
            if item.env:
                out.append(f"{pad}env:")
                for name, value in item.env:
                    out.append(
                        f"{pad}- {{name: {json.dumps(v(name))}, value: {json.dumps(v(value))}}}"
                    )
        return out

    def param(self, name: Value, value: PValue, pad: str) -> list[str]:
        lines = [f"{pad}- name: {yaml_str(self.t.value(name))}"]
        if value.dynamic is None:
            lines.append(f"{pad}  value: {_yaml_literal(value.literal)}")
        else:
            lines.append(f"{pad}  value: {yaml_str(self.t.value(value.dynamic))}")
        # the same type rule as XML: the YAML frontend guesses the type of text values too
        typed = dict(self.xml.param_attributes(value)).get("type")
        if typed is not None:
            lines.append(f"{pad}  type: {typed}")
        return lines


def _pair(key1: str, value1: str, key2: str, value2: str) -> str:
    return f"{{{key1}: {yaml_str(value1, flow=True)}, {key2}: {yaml_str(value2, flow=True)}}}"


def yaml_str(value: str, flow: bool = False) -> str:
    """Text as a YAML string: plain when YAML reads it back as this text, else quoted."""
    plain = (
        bool(value)
        and value == value.strip()
        and value[0] not in "-?:,[]{}#&*!|>'\"%@`"
        and not any(s in value for s in (": ", " #", "\n", "\t"))
        and not (flow and any(c in value for c in ",[]{}"))
        and not value.endswith(":")
        and reads_back(value)
    )
    return value if plain else json.dumps(value, ensure_ascii=False)


def _yaml_literal(value: Any) -> str:
    """A typed literal in YAML (strings quoted, so they stay strings)."""
    if isinstance(value, str):
        return yaml_str(value)
    return literal_text(value)


# --- the command --------------------------------------------------------------------------------

WRITERS: dict[str, Callable[[Source], Any]] = {
    "py": PythonWriter,
    "yaml": YamlWriter,
    "xml": XmlWriter,
}


def convert(path: str, fmt: str, output: str | None = None) -> str:
    """The ROS 2 launch file (text) the roslaunch file at ``path`` becomes."""
    if fmt not in WRITERS:
        raise UsageError(f"format {fmt!r} is not one of {', '.join(WRITERS)}")
    source = Source(os.path.abspath(path), output, fmt)
    items = r1.read(source.path)
    return str(WRITERS[fmt](source).write(items))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="mlaunch convert",
        description="Convert a ROS 1 roslaunch XML file to a ROS 2 launch file that resolves to"
        " the same plan as running the ROS 1 file with mlaunch.",
    )
    parser.add_argument("file", help="the ROS 1 .launch file")
    parser.add_argument(
        "--to",
        choices=sorted(WRITERS),
        help="output format (default: from the -o suffix, else py)",
    )
    parser.add_argument("-o", "--output", help="write here instead of standard output")
    parser.add_argument(
        "--package-path",
        action="append",
        default=[],
        metavar="DIR",
        help="extra folders to find source packages in (repeatable)",
    )
    parser.add_argument("-d", "--debug", action="store_true", help="tracebacks for errors")
    return parser


def _format_for(opts: argparse.Namespace) -> str:
    if opts.to:
        return str(opts.to)
    if opts.output:
        for fmt, suffix in FORMATS.items():
            short = suffix.removeprefix(".launch")
            if opts.output.endswith((suffix, short)) or (
                fmt == "yaml" and opts.output.endswith(".yml")
            ):
                return fmt
    return "py"


def main(argv: Sequence[str] | None = None) -> int:
    """``mlaunch convert ...``: 0 written, 2 bad input (one line on stderr)."""
    from mlaunch.cli import report_error

    args = list(sys.argv[1:] if argv is None else argv)
    opts = build_parser().parse_args(args)
    try:
        path = os.path.abspath(opts.file)
        if not os.path.isfile(path):
            raise LaunchFileError(f"launch file {opts.file!r} does not exist")
        from mlaunch.ros import packages

        packages.configure(search_paths=opts.package_path, launch_file=path, environ=os.environ)
        output = None if opts.output in (None, "-") else opts.output
        result = convert(path, _format_for(opts), output)
        if output is None:
            sys.stdout.write(result)
        else:
            try:
                with open(output, "w", encoding="utf-8") as f:
                    f.write(result)
            except OSError as e:
                raise UsageError(f"cannot write {output!r}: {e.strerror}")
        return 0
    except Exception as e:
        return report_error(e, opts.debug)


__all__ = ["ConversionError", "convert", "main"]
