"""The --check of a ``.launch.py`` file: names and keyword arguments Jazzy's launch does not have.

mlaunch serves the ``launch`` and ``launch_ros`` modules itself, with a few names and keyword
arguments of its own (``required=True``, ``YAMLLaunchDescriptionSource`` in
``launch.launch_description_sources``...). Under ros2 launch those are an ImportError or a
TypeError. The file is read, not run: its imports and the calls of imported classes are held to
mlaunch/check/jazzy_python.json, which was recorded from the reference (tests/conformance/
jazzy_python_api.py).
"""

from __future__ import annotations

import ast
import json
import os

from mlaunch.check import jazzy
from mlaunch.check.finding import Finding, reads_as_bool

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

_PACKAGES = ("launch", "launch_ros", "launch_xml", "launch_yaml")
# Classes mlaunch lets you join with ``/`` (newer launch has it; Jazzy does not).
_SLASH_JOINS = ("PathJoinSubstitution", "FindPackageShare", "FindPackagePrefix", "FindPackage")
_API: dict[str, Any] = {}
# Modules newer than Jazzy that mlaunch serves on Jazzy: what ros2 launch (Jazzy) lacks.
_NEWER = {
    "launch_testing_ros.actions": "EnableRmwIsolation is launch_testing_ros's after Jazzy"
    " (ros2/launch_ros#459)",
}


def api() -> dict[str, Any]:
    """Jazzy's modules, their exported names and their classes' keyword arguments."""
    if not _API:
        here = os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(here, "jazzy_python.json"), encoding="utf-8") as f:
            _API.update(json.load(f))
    return _API


def check_python(path: str) -> tuple[list[Finding], list[str]]:
    """Findings for the Python launch file at ``path`` (it includes nothing checkable)."""
    from mlaunch.plan.errors import LaunchFileError

    try:
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), filename=path)
    except (OSError, UnicodeDecodeError) as e:
        raise LaunchFileError(f"cannot read launch file: {e}", where=path)
    except SyntaxError as e:
        raise LaunchFileError(f"Python syntax error: {e.msg}", where=f"{path}:{e.lineno}")
    visitor = _Visitor(path)
    visitor.visit(tree)
    return visitor.findings, []


class _Visitor(ast.NodeVisitor):
    def __init__(self, path: str) -> None:
        self.path = path
        self.findings: list[Finding] = []
        # local name -> dotted Jazzy name ("launch_ros.actions.Node", or a module)
        self.names: dict[str, str] = {}
        # local variable -> the dotted Jazzy class of the call it was assigned from
        self.instances: dict[str, str] = {}

    def add(self, node: ast.AST, message: str) -> None:
        line = getattr(node, "lineno", 0)
        col = getattr(node, "col_offset", -1) + 1
        self.findings.append(Finding(f"{self.path}:{line}:{col}", message))

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            if self._module_known(node, alias.name):
                top = alias.name.split(".")[0]
                self.names[alias.asname or top] = alias.name if alias.asname else top

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        module = node.module or ""
        if node.level or not self._module_known(node, module):
            return
        exports = api()["exports"].get(module)
        for alias in node.names:
            dotted = f"{module}.{alias.name}"
            missing = exports is not None and alias.name != "*" and alias.name not in exports
            if missing and dotted in jazzy.NEWER_PYTHON:
                self.add(node, jazzy.newer(dotted, jazzy.NEWER_PYTHON[dotted]))
                continue
            if missing and dotted not in api()["modules"]:
                self.add(
                    node,
                    f"Jazzy's {module} has no {alias.name!r}: an ImportError under ros2 launch",
                )
                continue
            self.names[alias.asname or alias.name] = dotted

    def _module_known(self, node: ast.AST, module: str) -> bool:
        """Whether ``module`` is one Jazzy's launch has (False also for non-launch modules)."""
        top = module.split(".")[0]
        if module in _NEWER:
            self.add(
                node,
                f"Jazzy has no module {module!r}: an ImportError under ros2 launch (Jazzy);"
                f" {_NEWER[module]}, and mlaunch runs it",
            )
            return False
        if top == "mlaunch":
            self.add(node, f"imports {module!r}: mlaunch's own, not there under ros2 launch")
            return False
        if top not in _PACKAGES:
            return False
        if module in jazzy.NEWER_PYTHON:
            self.add(node, jazzy.newer(f"the module {module}", jazzy.NEWER_PYTHON[module]))
            return False
        if module not in api()["modules"]:
            self.add(node, f"Jazzy has no module {module!r}: an ImportError under ros2 launch")
            return False
        return True

    def visit_Assign(self, node: ast.Assign) -> None:
        if isinstance(node.value, ast.Call):
            dotted = self._dotted(node.value.func)
            for target in node.targets:
                if dotted and isinstance(target, ast.Name):
                    self.instances[target.id] = dotted
        self.generic_visit(node)

    def visit_BinOp(self, node: ast.BinOp) -> None:
        left = node.left
        if isinstance(left, ast.Call):
            dotted = self._dotted(left.func)
        else:
            dotted = self.instances.get(left.id) if isinstance(left, ast.Name) else None
        name = dotted.rsplit(".", 1)[1] if dotted else ""
        if isinstance(node.op, ast.Div) and name in _SLASH_JOINS:
            self.add(
                node,
                f"Jazzy's {name} has no '/' operator (newer launch has): a TypeError under"
                " ros2 launch; write PathJoinSubstitution([a, b])",
            )
        self.generic_visit(node)

    def visit_Call(self, node: ast.Call) -> None:
        dotted = self._dotted(node.func)
        keywords = api()["keywords"].get(dotted) if dotted else None
        if dotted and keywords is not None:
            for kw in node.keywords:
                if kw.arg is not None and kw.arg not in keywords:
                    self.add(
                        kw.value,
                        f"Jazzy's {dotted.rsplit('.', 1)[1]} takes no {kw.arg}=: a TypeError"
                        " under ros2 launch",
                    )
        for kw in node.keywords:
            value = kw.value
            if (
                kw.arg == "respawn"
                and isinstance(value, ast.Constant)
                and isinstance(value.value, str)
                and not reads_as_bool(value.value)
            ):
                self.add(
                    value,
                    f"Jazzy reads respawn as a boolean; {value.value!r} is mlaunch's own"
                    " (use True or False)",
                )
        self.generic_visit(node)

    def _dotted(self, func: ast.expr) -> str | None:
        """The Jazzy name a call target refers to, through the file's imports."""
        chain: list[str] = []
        while isinstance(func, ast.Attribute):
            chain.append(func.attr)
            func = func.value
        if not isinstance(func, ast.Name) or func.id not in self.names:
            return None
        return ".".join([self.names[func.id], *reversed(chain)])
