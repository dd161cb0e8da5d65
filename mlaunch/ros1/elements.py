"""A roslaunch file's XML elements, and how their attributes and ``$(...)`` args are read."""

from __future__ import annotations

import ast
import os
from dataclasses import dataclass, field
from typing import Any
from xml.parsers import expat

from mlaunch.frontends.encoding import not_utf8
from mlaunch.frontends.limits import DEPTH_LIMIT, too_deep
from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.ros1.eval import EvalCutter
from mlaunch.ros1.model import (
    AnonRef,
    ArgRef,
    Cond,
    DirnameRef,
    EnvRef,
    EvalRef,
    FindRef,
    NodeItem,
    Part,
    ProcessItem,
    Ref,
    Value,
    Warn,
    merge,
    static_text,
)
from mlaunch.ros1.scope import Desc, Out, Scope
from mlaunch.ros1.values import convert_value, program_paths, resolve_static, rewrite_xacro


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
        if len(stack) >= DEPTH_LIMIT:
            raise too_deep(f"{path}:{parser.CurrentLineNumber}", "XML elements")
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
        invalid_token = e.code == expat.errors.codes[expat.errors.XML_ERROR_INVALID_TOKEN]
        raise (invalid_token and not_utf8(data, path)) or LaunchFileError(
            f"malformed XML: {expat.ErrorString(e.code)}", where=f"{path}:{e.lineno}"
        )
    return roots[0]


SUBSTITUTION_ARITY = {"arg": (1, 1), "find": (1, 1), "env": (1, 1), "anon": (1, 1)}
SUBSTITUTION_ARITY.update({"optenv": (1, 99), "dirname": (0, 0)})

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
    "machine": (
        "name",
        "address",
        "env-loader",
        "default",
        "user",
        "password",
        "ssh-port",
        "timeout",
        "ros-root",
        "ros-package-path",
        "ros-ip",
        "ros-host-name",
    ),
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


class ElementReader:
    """Reads the elements of one roslaunch file: attributes, values, conditions and errors."""

    def __init__(self, path: str) -> None:
        self.path = os.path.abspath(path)
        self._index: Any = None
        self.converting = False  # writing a file for elsewhere: nothing depends on this machine
        self.descriptions: list[Desc] = []
        self.arbotix: list[tuple[NodeItem, ProcessItem, NodeItem, str]] = []
        self.jsp_nodes: list[NodeItem] = []
        # values ROS 2 cannot hold met while reading one tag (each its own warning)
        self.unheld: list[str] = []
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

    def check_attributes(self, el: Element, out: Out) -> None:
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

    def attr(
        self, el: Element, name: str, scope: Scope, required: bool = False, program: bool = True
    ) -> Value | None:
        """An attribute's value; ``program`` false: ``$(find xacro)/xacro`` stays a path (an
        argument of another program), not the xacro command."""
        raw = el.attrs.get(name)
        if raw is None:
            if required:
                raise self.error(el, f"missing required attribute {name!r}")
            return None
        return self.value(raw, el, name, scope, program)

    def literal(self, el: Element, name: str, scope: Scope, required: bool = False) -> str | None:
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

    def flag(self, el: Element, name: str, scope: Scope) -> bool | Value | None:
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

    def condition(self, el: Element, scope: Scope) -> Cond | None:
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

    def value(self, raw: str, el: Element, attr: str, scope: Scope, program: bool = True) -> Value:
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
        return rewrite_xacro(merge(parts)) if program else program_paths(merge(parts))

    def substitution(self, body: str, el: Element, attr: str, raw: str, scope: Scope) -> Ref:
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

    def check_arg(self, name: str, el: Element, scope: Scope) -> None:
        if name not in scope.args:
            raise self.error(
                el,
                f"arg {name!r} is not defined (declare it with <arg name={name!r} .../> before"
                " it is used)",
            )

    def eval(self, expression: str, el: Element, scope: Scope) -> EvalRef:
        """``$(eval ...)``, checked now: Python syntax, no ``__``, every name known."""
        if "__" in expression:
            raise self.error(el, "$(eval ...) may not contain double underscore expressions")
        try:
            tree = ast.parse(expression.strip(), mode="eval")
        except SyntaxError as e:
            raise self.error(el, f"$(eval {expression}): Python syntax error: {e.msg}")
        return EvalRef(expression, EvalCutter(self, el, scope, expression.strip()).cut(tree))

    def arg_kind(self, name: str, scope: Scope) -> str:
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
