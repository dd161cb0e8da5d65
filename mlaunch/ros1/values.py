"""roslaunch's value rules: param types, rosparam YAML, static paths and ``args`` splitting."""

from __future__ import annotations

import ast
import math
import os
import re
import shlex
from typing import Any

import yaml

from mlaunch.plan.errors import LaunchFileError
from mlaunch.ros1.model import DirnameRef, ExecRef, FindRef, Part, Value, merge

_XACRO = re.compile(r"^/xacro(\.py)?(?=\s)")


def convert_value(value: str, type_name: str) -> Any:
    """roslaunch's ``convert_value``: text to the param type (``auto`` guesses as roslaunch)."""
    kind = type_name.lower()
    if kind == "auto":
        try:
            if "." in value:
                return float(value)
            if "_" not in value:  # Python reads 1_000 as a number; roslaunch keeps it text
                return int(value)
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
        from mlaunch.plan.yamldata import load as load_yaml

        return load_yaml(value, loader=RosparamLoader)
    raise ValueError(f"unknown type {type_name!r}")


PARAM_TYPES = ("str", "string", "int", "double", "bool", "boolean", "yaml", "auto")
# The ROS 2 type a dynamic value of each roslaunch type is forced to (None: YAML rules).
VTYPES: dict[str, type | None] = {
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


def rewrite_xacro(value: Value) -> Value:
    """``$(find xacro)/xacro[.py] FILE`` runs xacro: the ``xacro`` program (in-process)."""
    parts = list(value)
    for i in range(len(parts) - 1):
        nxt = parts[i + 1]
        if parts[i] == FindRef("xacro") and isinstance(nxt, str) and _XACRO.match(nxt):
            parts[i] = "xacro"
            parts[i + 1] = _XACRO.sub("", nxt)
    return merge(parts)


_PROGRAM = re.compile(r"^/(xacro)(\.py)?(?=\s|$)")


def program_paths(value: Value) -> Value:
    """``$(find xacro)/xacro`` as an argument of another program (an ``env_run`` wrapper): the
    path of the xacro program, as roslaunch found it (not the in-process ``xacro`` command)."""
    parts = list(value)
    for i in range(len(parts) - 1):
        nxt = parts[i + 1]
        found = _PROGRAM.match(nxt) if isinstance(nxt, str) else None
        if parts[i] == FindRef("xacro") and found is not None and isinstance(nxt, str):
            parts[i] = ExecRef("xacro", found.group(1))
            parts[i + 1] = nxt[found.end() :]
    return merge(parts)


def dotted(name: str) -> str:
    """A ROS 1 parameter path as a ROS 2 parameter name (``a/b`` -> ``a.b``)."""
    return ".".join(p for p in name.split("/") if p)


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
                args.append(merge(current))
                current = []
            continue
        glued_left = not part[0].isspace()
        glued_right = not part[-1].isspace()
        for index, word in enumerate(words):
            if index == 0 and glued_left:
                current.append(word)
            else:
                if current:
                    args.append(merge(current))
                current = [word]
            if index == len(words) - 1 and not glued_right:
                args.append(merge(current))
                current = []
    if current:
        args.append(merge(current))
    return args
