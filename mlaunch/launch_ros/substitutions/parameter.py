"""``launch_ros.substitutions.parameter``: the value of a global parameter."""

from __future__ import annotations

import collections.abc

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class Parameter(Substitution):
    """The value a SetParameter in scope gave a global parameter (``$(param name [default])``)."""

    def __init__(self, name: SomeSubstitutionsType, *, default: Any = None) -> None:
        self.name = normalize(name)
        self.default = None if default is None else normalize(_default_items(default))

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        for entry in context.launch_configurations.get("global_params", ()):
            if isinstance(entry, tuple) and entry[0] == name:
                return str(entry[1])
        if self.default is None:
            raise SubstitutionFailure(
                f"parameter {name!r} not found (set it with SetParameter / <set_parameter>"
                " before this point, or give a default)"
            )
        return perform_substitutions(context, self.default)

    def describe(self) -> str:
        return f"Parameter(name={describe(self.name)})"


def _default_items(default: Any) -> list[Any]:
    """launch_ros turns every default item that is not text or a substitution into str()."""
    items = default if isinstance(default, collections.abc.Iterable) else (default,)
    if isinstance(default, str):
        items = (default,)
    return [i if isinstance(i, (str, Substitution)) else str(i) for i in items]
