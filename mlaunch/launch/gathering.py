"""How a package of the launch API serves its names: each from the module that defines it.

Upstream's ``__init__`` imports every module of its package; mlaunch's gathers the names and
imports a module when one of its names is first asked for, so a launch file that uses two
actions loads two modules (the path to the first child is a start-up budget). A package's
``__init__`` makes one ``Gathered`` and serves its ``attribute`` and ``listing`` as the module's
``__getattr__`` and ``__dir__``.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping
    from typing import Any


class Gathered:
    """The names a package serves (name -> the module that defines it, ``.module`` for one of
    the package's own, or (module, attribute) when the package serves it under another name)
    and the submodules it loads on first use."""

    __slots__ = ("names", "namespace", "package", "submodules")

    def __init__(
        self,
        namespace: dict[str, Any],
        names: Mapping[str, str | tuple[str, str]],
        submodules: Iterable[str] = (),
    ) -> None:
        self.namespace = namespace
        self.package: str = namespace["__name__"]
        self.names = dict(names)
        self.submodules = frozenset(submodules)

    def attribute(self, name: str) -> Any:
        """The package's ``__getattr__``: the name loaded from its module, then kept."""
        where = self.names.get(name)
        if where is not None:
            module, attribute = (where, name) if isinstance(where, str) else where
            value = getattr(importlib.import_module(module, self.package), attribute)
        elif name in self.submodules:
            value = importlib.import_module(f"{self.package}.{name}")
        else:
            raise AttributeError(f"module {self.package!r} has no attribute {name!r}")
        self.namespace[name] = value
        return value

    def listing(self) -> list[str]:
        """The package's ``__dir__``: what it holds now and every name it serves."""
        return sorted({*self.namespace, *self.names, *self.submodules})
