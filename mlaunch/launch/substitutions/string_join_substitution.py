"""``launch.substitutions.string_join_substitution``: StringJoinSubstitution, newer than Jazzy
(launch 3.8.1, Kilted; its ``$(string-join DELIMITER A B ...)`` form launch 3.9.5, Rolling)."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Subs,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class StringJoinSubstitution(Substitution):
    """The components, each performed and concatenated, joined with ``delimiter``."""

    def __init__(
        self, substitutions: Iterable[SomeSubstitutionsType], delimiter: SomeSubstitutionsType = ""
    ) -> None:
        self._substitutions = [normalize(component) for component in substitutions]
        self._delimiter = normalize(delimiter)

    @property
    def substitutions(self) -> list[Subs]:
        return self._substitutions

    @property
    def delimiter(self) -> Subs:
        return self._delimiter

    @classmethod
    def parse(cls, data: Sequence[Any]) -> tuple[type[StringJoinSubstitution], dict[str, Any]]:
        if len(data) < 2:
            raise TypeError(
                "string-join substitution expects at least 2 arguments: 1 delimiter + at least"
                " 1 component"
            )
        return cls, {"delimiter": data[0], "substitutions": list(data[1:])}

    def perform(self, context: LaunchContext) -> str:
        parts = [perform_substitutions(context, c) for c in self._substitutions]
        return perform_substitutions(context, self._delimiter).join(parts)

    def describe(self) -> str:
        parts = ", ".join(describe(c) for c in self._substitutions)
        return f"StringJoinSubstitution([{parts}], delimiter={describe(self._delimiter)})"


__all__ = ["StringJoinSubstitution"]
