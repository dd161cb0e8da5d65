"""ROS 2's ``launch.frontend``: the API markup frontends build on (Entity, Parser, expose_*).

Third-party packages register tags and substitutions with ``expose_action`` /
``expose_substitution``; ``Parser.load`` finds the XML and YAML implementations through entry
points. The names are loaded on first use (PEP 562): the readers import
``mlaunch.launch.frontend.template`` on every YAML/XML launch, and that must not pay for the rest.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.frontend import type_utils
    from mlaunch.launch.frontend.entity import Entity
    from mlaunch.launch.frontend.expose import expose_action, expose_substitution
    from mlaunch.launch.frontend.parser import InvalidFrontendLaunchFileError, Parser

# Each public name and the submodule that defines it.
_HOMES = {
    "Entity": "entity",
    "InvalidFrontendLaunchFileError": "parser",
    "Parser": "parser",
    "expose_action": "expose",
    "expose_substitution": "expose",
}


def __getattr__(name: str) -> Any:
    if name == "type_utils":
        return importlib.import_module(f"{__name__}.type_utils")
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{home}"), name)


__all__ = [
    "Entity",
    "InvalidFrontendLaunchFileError",
    "Parser",
    "expose_action",
    "expose_substitution",
    "type_utils",
]
