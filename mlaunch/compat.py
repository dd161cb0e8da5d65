"""The module names unmodified ROS 2 launch files import, served by mlaunch while it loads them.

``install()`` puts a finder first on ``sys.meta_path`` that answers ``launch``, ``launch.actions``,
``launch_ros.actions``, ``ament_index_python.packages`` ... with mlaunch's own modules. Nothing is
installed on disk, so a real ROS installation on the same machine is never shadowed outside
mlaunch, and inside mlaunch every description is built from classes mlaunch can resolve.
"""

from __future__ import annotations

import importlib
import sys
from importlib.machinery import ModuleSpec, PathFinder

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from types import ModuleType
    from typing import Any

# The ROS 2 top-level packages and the mlaunch package serving each: ``launch.X.Y`` is
# ``mlaunch.launch.X.Y``, and so on (a prefix rule: a new module needs no entry here).
ROOTS: dict[str, str] = {
    "launch": "mlaunch.launch",
    "launch_ros": "mlaunch.launch_ros",
    "launch_xml": "mlaunch.frontends.launch_xml",
    "launch_yaml": "mlaunch.frontends.launch_yaml",
    "ament_index_python": "mlaunch.ros.ament_index",
    "launch_testing": "mlaunch.launch_testing",
    "launch_testing_ros": "mlaunch.launch_testing_ros",
    "launch_pytest": "mlaunch.launch_pytest",
}

# Upstream modules that mlaunch serves from a module of another name: ``launch.launch_service``
# runs the engine (an application), launch_xml's and launch_yaml's are mlaunch's readers'.
SYNONYMS: dict[str, str] = {
    "launch.launch_service": "mlaunch.app.launch_service",
    "launch_xml.launch_description_sources": "mlaunch.launch.launch_description_sources",
    "launch_xml.parser": "mlaunch.frontends.launch_xml",
    "launch_xml.entity": "mlaunch.frontends.launch_xml",
    "launch_yaml.launch_description_sources": "mlaunch.launch.launch_description_sources",
    "launch_yaml.parser": "mlaunch.frontends.launch_yaml",
    "launch_yaml.entity": "mlaunch.frontends.launch_yaml",
    "ament_index_python.packages": "mlaunch.ros.ament_index",
}


def target_of(fullname: str) -> str | None:
    """The mlaunch module that serves the ROS 2 module ``fullname``, or None if none does."""
    if fullname in SYNONYMS:
        return SYNONYMS[fullname]
    root, dot, rest = fullname.partition(".")
    base = ROOTS.get(root)
    if base is None:
        return None
    return base + dot + rest


# Plain classes, not importlib.abc's: importing importlib.abc pulls in importlib.resources and
# pathlib (~7 ms), and the import system only needs these methods.
class _AliasLoader:
    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: ModuleSpec) -> ModuleType:
        return importlib.import_module(self.target)

    def exec_module(self, module: ModuleType) -> None:
        return None


class AliasFinder:
    """Answers the ROS 2 module names with mlaunch modules."""

    def find_spec(self, fullname, path=None, target=None):  # type: ignore[no-untyped-def]
        target_name = target_of(fullname)
        if target_name is None:
            return None
        if not _exists(target_name):
            return None
        is_package = fullname in ROOTS or any(s.startswith(fullname + ".") for s in SYNONYMS)
        loader: Any = _AliasLoader(target_name)
        return ModuleSpec(fullname, loader, is_package=is_package)


def _exists(name: str) -> bool:
    """Whether the module ``name`` can be imported (its package is imported to look).

    What importlib.util.find_spec says, without importing importlib.util (and contextlib with
    it, ~1 ms before the first child): mlaunch's modules are plain files on their package's path.
    """
    if name in sys.modules:
        return True
    package, _, _ = name.rpartition(".")
    path = None
    if package:
        path = getattr(importlib.import_module(package), "__path__", None)
        if path is None:
            return False
    return PathFinder.find_spec(name, path) is not None


_FINDER = AliasFinder()


def install() -> None:
    """Serve the ROS 2 names from now on in this process (idempotent)."""
    if _FINDER in sys.meta_path:
        return
    import mlaunch.launch

    mlaunch.launch.provide("LaunchService", "mlaunch.app.launch_service", "LaunchService")
    sys.meta_path.insert(0, _FINDER)
    # A real launch/launch_ros/ament_index_python imported earlier must not win.
    for name in list(sys.modules):
        module = sys.modules[name]
        if target_of(name) is not None and not module.__name__.startswith("mlaunch"):
            del sys.modules[name]
