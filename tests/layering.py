"""mlaunch's layers, bottom to top, and the reader of the imports that must respect them.

Every package of ``mlaunch`` (a folder, or a top-level module) sits in exactly one layer. A
module may import its own package, and any package of its own layer or a lower one; an import
from a lower layer into a higher one is a back-edge, and no two packages may import each other,
directly or around a circle. Every kind of import counts: top-level, function-local, under
``TYPE_CHECKING``, and module names written as strings (tables that ``importlib`` reads), but
not names that only appear in docstrings.
"""

from __future__ import annotations

import ast
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache

LAYERS: list[tuple[str, frozenset[str]]] = [
    ("plan", frozenset({"plan", "schemas"})),
    ("launch API", frozenset({"ros", "standins", "launch", "launch_ros", "machines"})),
    ("readers", frozenset({"frontends", "ros1", "readers"})),
    ("resolve", frozenset({"resolve"})),
    ("engine", frozenset({"engine"})),
    ("parts", frozenset({"parts", "smoke"})),
    (
        "applications",
        frozenset(
            {
                "app",
                "commands",
                "cli",
                "check",
                "convert",
                "export",
                "launch_testing",
                "launch_pytest",
                "launch_testing_ros",
                "testing",
                "actions",
                "compat",
                "__main__",
                "__init__",
            }
        ),
    ),
]

_DOTTED = re.compile(r"^mlaunch(?:\.[A-Za-z_][A-Za-z0-9_]*)+$")


@dataclass(frozen=True)
class Import:
    """One import of one mlaunch module by another, with where it is written."""

    source: str  # the importing module, dotted
    target: str  # the imported module, dotted (the longest prefix that is a module)
    path: str
    line: int
    kind: str  # "import", or "string" for a module name written as text

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.source} -> {self.target} ({self.kind})"


def modules(root: str) -> dict[str, str]:
    """Every module below ``root`` (the ``mlaunch`` folder): dotted name -> file path."""
    found: dict[str, str] = {}
    base = os.path.dirname(os.path.abspath(root))
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                dotted = os.path.relpath(path, base)[:-3].replace(os.sep, ".")
                found[dotted.removesuffix(".__init__")] = path
    return found


def package_of(module: str) -> str:
    """The package a module belongs to: ``mlaunch.engine.output`` -> ``engine``; the root's own
    ``__init__`` is ``__init__``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def layer_of(package: str) -> int:
    for index, (_, members) in enumerate(LAYERS):
        if package in members:
            return index
    raise KeyError(f"package {package!r} is in no layer: add it to tests/layering.py LAYERS")


def _docstrings(tree: ast.AST) -> set[int]:
    ids: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                ids.add(id(body[0].value))
    return ids


def _resolve(name: str, known: dict[str, str]) -> str | None:
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def imports(root: str) -> Iterator[Import]:
    """Every import between mlaunch modules below ``root``."""
    known = modules(root)
    seen: set[tuple[str, str, int]] = set()
    for module, path in sorted(known.items()):
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        is_package = path.endswith("__init__.py")
        skip = _docstrings(tree)
        for node in ast.walk(tree):
            line = getattr(node, "lineno", 0)
            for target, kind in _targets(node, module, is_package, known, skip):
                if target != module and (target, path, line) not in seen:
                    seen.add((target, path, line))
                    yield Import(module, target, path, line, kind)


def _targets(
    node: ast.AST, module: str, is_package: bool, known: dict[str, str], skip: set[int]
) -> Iterator[tuple[str, str]]:
    if isinstance(node, ast.Import):
        for alias in node.names:
            if alias.name.startswith("mlaunch"):
                found = _resolve(alias.name, known)
                if found:
                    yield found, "import"
    elif isinstance(node, ast.ImportFrom):
        base = node.module or ""
        if node.level:
            parts = module.split(".")[: None if is_package else -1]
            parts = parts[: len(parts) - (node.level - 1)]
            base = ".".join(parts + ([base] if base else []))
        if base.startswith("mlaunch"):
            for alias in node.names:
                found = _resolve(f"{base}.{alias.name}", known)
                if found:
                    yield found, "import"
    elif (
        isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in skip
        and _DOTTED.match(node.value)
    ):
        found = _resolve(node.value, known)
        if found and found != "mlaunch":  # text naming no module of the package
            yield found, "string"


@cache
def _all_imports(root: str) -> tuple[Import, ...]:
    return tuple(imports(root))


def back_edges(root: str) -> list[Import]:
    """Imports from a lower layer into a higher one."""
    return [
        edge
        for edge in _all_imports(root)
        if layer_of(package_of(edge.source)) < layer_of(package_of(edge.target))
    ]


def package_cycles(root: str) -> list[list[str]]:
    """Circles between packages (each as its packages, sorted), by the imports above."""
    graph: dict[str, set[str]] = {}
    for edge in _all_imports(root):
        a, b = package_of(edge.source), package_of(edge.target)
        if a != b:
            graph.setdefault(a, set()).add(b)
    return _components(graph)


def _components(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan's), each sorted."""
    found: list[list[str]] = []
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()

    def connect(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in index:
                connect(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for node in sorted(graph):
        if node not in index:
            connect(node)
    return sorted(found)


def module_cycles(root: str) -> list[list[str]]:
    """Circles between the modules of one package (each as its modules, dotted, sorted), by the
    same imports as the layers: what makes a module impossible to read or change alone."""
    graph: dict[str, set[str]] = {}
    for edge in _all_imports(root):
        if package_of(edge.source) == package_of(edge.target):
            graph.setdefault(edge.source, set()).add(edge.target)
    return _components(graph)
