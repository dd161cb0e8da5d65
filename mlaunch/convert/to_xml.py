"""``mlaunch convert --to xml``: the description as a launch_xml file."""

from __future__ import annotations

import re
from xml.sax.saxutils import escape

from mlaunch.convert.writing import (
    SCOPED_NOTE,
    WIDTH,
    Source,
    Templates,
    comments,
    file_header,
    literal_text,
    reads_back,
    wrap,
)
from mlaunch.ros1.model import (
    MACHINE_FIELDS,
    DeclareArg,
    Dropped,
    Group,
    Include,
    Item,
    MachineItem,
    NodeItem,
    Process,
    ProcessItem,
    PValue,
    SetArg,
    SetEnv,
    SetParam,
    SetRemap,
    Value,
    Warn,
)


class XmlWriter:
    """The description as a launch_xml file."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.t = Templates(source)

    def write(self, items: list[Item]) -> str:
        header = file_header(self.source, "", "", "     ")
        note = [
            f"<!-- {line.removeprefix('@ ')} -->"
            for line in SCOPED_NOTE.format(c="@").split("\n")
            if line
        ]
        lines = ['<?xml version="1.0"?>', f"<!-- {header.strip()} -->", *note, "<launch>"]
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
            MachineItem: "machine",
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
        elif isinstance(item, MachineItem):
            attrs += [("name", v(item.name)), ("address", v(item.address))]
            attrs += [(a, v(getattr(item, k))) for k, a in MACHINE_FIELDS if getattr(item, k)]
        if item.condition is not None:
            key = "unless" if item.condition.unless else "if"
            attrs.append((key, v(item.condition.value)))
        return attrs

    def process(self, item: Process) -> list[tuple[str, str]]:
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
        if item.machine is not None:
            attrs.append(("machine", v(item.machine)))
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
