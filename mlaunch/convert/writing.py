"""What the writers of ``mlaunch convert`` share: the source, comments, literals, templates.

``Templates`` writes values in the ``$(...)`` language of launch_xml and launch_yaml.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from typing import Any

import yaml

from mlaunch.plan.errors import MlaunchError
from mlaunch.ros1.model import (
    AnonRef,
    ArgRef,
    CommandRef,
    DirnameRef,
    EnvRef,
    EvalRef,
    ExecRef,
    FileRef,
    FindRef,
    Include,
    Item,
    Part,
    Process,
    SetParam,
    Value,
    Warn,
    merge,
)
from mlaunch.ros1.values import resolve_static

FORMATS = {"py": ".launch.py", "yaml": ".launch.yaml", "xml": ".launch.xml"}
WIDTH = 99


class ConversionError(MlaunchError):
    """Something the ROS 1 file does that the chosen ROS 2 format cannot write."""


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
            path = resolve_static(item.path, self.path)
        except MlaunchError as e:  # a package not here: ROS 2 will look it up when launching
            return item.path, f"cannot check for a converted twin of the included file: {e}"
        last = item.path[-1] if item.path else ""
        ros1 = next((s for s in (".launch", ".launch.xml") if path and path.endswith(s)), None)
        if path is None or ros1 is None or not isinstance(last, str):
            return item.path, None
        suffix = FORMATS[self.fmt]
        stem = path[: -len(ros1)]
        if suffix != ros1 and os.path.exists(stem + suffix):
            return (*item.path[:-1], last[: -len(ros1)] + suffix), None
        name = os.path.basename(path)
        how = "mlaunch includes it as it is, ROS 2 cannot"
        if ros1 == ".launch.xml":
            how = "roslaunch reads every include as ROS 1 XML, ROS 2 would read it as ROS 2 XML"
        other = "py" if suffix == ros1 else self.fmt
        return item.path, (
            f"{name} is a ROS 1 file: {how} (convert it too: mlaunch convert {name} --to {other}"
            f" -o {os.path.basename(stem)}{FORMATS[other]})"
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
    found = [*item.warnings, *item.scope_notes, *format_warnings(item, source)]
    out += [f"WARNING: {w}" for w in found]
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
    if isinstance(item, Process) and item.required not in (True, False):
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
        read_back: object = yaml.safe_load(value)
        return read_back == value
    except yaml.YAMLError:
        return True


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
        if isinstance(part, ExecRef):
            program = self.arg(part.executable, nested)
            return f"$(exec-in-pkg {program} {self.arg(part.package, nested)})"
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
    return merge(out)


# ROS 1 global parameters belong to their group; ROS 2's SetParameter in a scoped group also
# reaches the nodes after it. roslaunch's $(dirname) in an include's arg, and after the include,
# is the includer's folder; ros2 launch (Jazzy) gives the included file's. The comments keep
# ROS 1's meaning under mlaunch (mlaunch.launch_ros.scope, mlaunch.launch.file_locals).
SCOPED_NOTE = (
    "{c} ROS 1 group parameters stay in their group under mlaunch (the comment below);\n"
    "{c} under ros2 launch a SetParameter in a group also reaches the nodes after it.\n"
    "{c} mlaunch: scoped-parameters\n"
    "{c} $(dirname) in an include's argument, and after it, stays this file's folder under\n"
    "{c} mlaunch (the comment below); under ros2 launch it is the included file's.\n"
    "{c} mlaunch: scoped-file-locals\n"
)


def file_header(source: Source, opening: str, closing: str, prefix: str = "") -> str:
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
