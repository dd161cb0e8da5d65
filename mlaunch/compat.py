"""The module names unmodified ROS 2 launch files import, served by mlaunch while it loads them.

``install()`` puts a finder first on ``sys.meta_path`` that answers ``launch``, ``launch.actions``,
``launch_ros.actions``, ``ament_index_python.packages`` ... with mlaunch's own modules. Nothing is
installed on disk, so a real ROS installation on the same machine is never shadowed outside
mlaunch, and inside mlaunch every description is built from classes mlaunch can resolve.
"""

from __future__ import annotations

import importlib
import sys
from importlib.machinery import ModuleSpec

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from types import ModuleType
    from typing import Any

ALIASES: dict[str, str] = {
    "launch": "mlaunch.launch_api",
    "launch.actions": "mlaunch.actions",
    "launch.action": "mlaunch.actions",
    "launch.substitutions": "mlaunch.substitutions",
    "launch.substitution": "mlaunch.substitutions",
    "launch.conditions": "mlaunch.conditions",
    "launch.condition": "mlaunch.conditions",
    "launch.event_handlers": "mlaunch.event_handlers",
    "launch.event_handler": "mlaunch.event_handlers",
    "launch.events": "mlaunch.events",
    "launch.events.process": "mlaunch.events",
    "launch.event": "mlaunch.events",
    "launch.launch_description": "mlaunch.actions",
    "launch.launch_description_entity": "mlaunch.actions",
    "launch.launch_description_sources": "mlaunch.launch_description_sources",
    "launch.launch_context": "mlaunch.context",
    "launch.some_substitutions_type": "mlaunch.substitutions",
    "launch.utilities": "mlaunch.launch_api",
    "launch.frontend": "mlaunch.launch_api",
    "launch_xml": "mlaunch.launch_description_sources",
    "launch_xml.launch_description_sources": "mlaunch.launch_description_sources",
    "launch_yaml": "mlaunch.launch_description_sources",
    "launch_yaml.launch_description_sources": "mlaunch.launch_description_sources",
    "launch_ros": "mlaunch.ros.api",
    "launch_ros.actions": "mlaunch.ros.actions",
    "launch_ros.substitutions": "mlaunch.ros.substitutions",
    "launch_ros.parameter_descriptions": "mlaunch.ros.parameter_descriptions",
    "launch_ros.descriptions": "mlaunch.ros.parameter_descriptions",
    "launch_ros.event_handlers": "mlaunch.ros.events",
    "launch_ros.events": "mlaunch.ros.events",
    "launch_ros.events.lifecycle": "mlaunch.ros.events",
    "launch_ros.utilities": "mlaunch.ros.api",
    "ament_index_python": "mlaunch.ros.ament_index",
    "ament_index_python.packages": "mlaunch.ros.ament_index",
}


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
        target_name = ALIASES.get(fullname)
        if target_name is None:
            return None
        is_package = any(alias.startswith(fullname + ".") for alias in ALIASES)
        loader: Any = _AliasLoader(target_name)
        return ModuleSpec(fullname, loader, is_package=is_package)


_FINDER = AliasFinder()


def install() -> None:
    """Serve the ROS 2 names from now on in this process (idempotent)."""
    if _FINDER in sys.meta_path:
        return
    sys.meta_path.insert(0, _FINDER)
    # A real launch/launch_ros/ament_index_python imported earlier must not win.
    for name in list(sys.modules):
        if name in ALIASES and not sys.modules[name].__name__.startswith("mlaunch"):
            del sys.modules[name]
