"""``launch.substitutions.path_join_substitution``: paths joined (and ``PathSubstitution``,
which joins with ``/``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class PathJoinSubstitution(Substitution):
    """``os.path.join`` of the performed parts; ``/`` extends it."""

    def __init__(self, substitutions: Iterable[SomeSubstitutionsType]) -> None:
        self.substitutions = tuple(normalize(part) for part in substitutions)

    def perform(self, context: LaunchContext) -> str:
        parts = [perform_substitutions(context, part) for part in self.substitutions]
        return os.path.join(*parts) if parts else ""

    def __truediv__(self, other: SomeSubstitutionsType) -> PathJoinSubstitution:
        joined = PathJoinSubstitution([])
        joined.substitutions = (*self.substitutions, normalize(other))
        return joined

    def describe(self) -> str:
        return "PathJoin(" + ", ".join(describe(p) for p in self.substitutions) + ")"


class PathSubstitution(Substitution):
    """A path that ``/`` extends into a PathJoinSubstitution (Jazzy's ``PathSubstitution``)."""

    def __init__(self, path: SomeSubstitutionsType) -> None:
        self.path = normalize(path)

    def perform(self, context: LaunchContext) -> str:
        return perform_substitutions(context, self.path)

    def __truediv__(self, other: SomeSubstitutionsType) -> PathJoinSubstitution:
        return PathJoinSubstitution([self, other])

    def describe(self) -> str:
        return f"Path({describe(self.path)})"
