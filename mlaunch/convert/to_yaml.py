"""``mlaunch convert --to yaml``: the description as a launch_yaml file."""

from __future__ import annotations

import json
from typing import Any

from mlaunch.convert.to_xml import XmlWriter
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
    Dropped,
    Group,
    Include,
    Item,
    NodeItem,
    ProcessItem,
    PValue,
    SetParam,
    Value,
    Warn,
)


class YamlWriter:
    """The description as a launch_yaml file."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.t = Templates(source)
        self.xml = XmlWriter(source)  # shares the attribute choices

    def write(self, items: list[Item]) -> str:
        header = file_header(self.source, "", "", "# ")
        lines = [header, "", SCOPED_NOTE.format(c="#").rstrip("\n"), "launch:"]
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
        """Attribute values are text, as Jazzy's launch_yaml reads them (a YAML boolean or
        number where it wants text is a TypeError there); only the attributes it reads typed
        (scoped, respawn_delay) keep their YAML type. set_parameter's value is text that
        launch_ros types as YAML, so "false" still sets a boolean."""
        if key == "scoped" and value in ("true", "false"):
            return value
        if key == "respawn_delay" and isinstance(getattr(item, "respawn_delay", None), float):
            return value
        if key == "value" and isinstance(item, SetParam) and item.value.dynamic is None:
            return yaml_str(literal_text(item.value.literal))
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
