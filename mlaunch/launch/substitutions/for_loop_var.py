"""``launch.substitutions.for_loop_var``: ForEachVar and ForLoopIndex, newer than Jazzy
(launch 3.8, Kilted): the value of a ForEach iteration's variable, or of a ForLoop's index,
from the locals the loop's iteration set (mlaunch.launch.actions.for_loop)."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Subs,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class ForEachVar(Substitution):
    """``$(for-var NAME [default])``: the iteration's value of NAME."""

    def __init__(
        self, name: SomeSubstitutionsType, *, default_value: SomeSubstitutionsType | None = None
    ) -> None:
        self._name = normalize(name)
        self._default_value = None if default_value is None else normalize(default_value)

    @property
    def name(self) -> Subs:
        return self._name

    @property
    def default_value(self) -> Subs | None:
        return self._default_value

    @classmethod
    def parse(cls, data: Sequence[Any]) -> tuple[type[ForEachVar], dict[str, Any]]:
        if len(data) not in (1, 2):
            raise ValueError(f"{cls.__name__} substitution expects 1 or 2 arguments")
        kwargs: dict[str, Any] = {"name": data[0]}
        if len(data) == 2:
            kwargs["default_value"] = data[1]
        return cls, kwargs

    @staticmethod
    def get_local_arg_name(name: str) -> str:
        return f"ForEachVar__{name}"

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self._name)
        values = context.get_locals_as_dict()
        key = self.get_local_arg_name(name)
        if key in values:
            return str(values[key])
        if self._default_value is None:
            raise SubstitutionFailure(
                f"no value for {self.__class__.__name__} {name!r} here, and no default value"
                " (it is set only inside a for_each or for loop whose values name it)"
            )
        return perform_substitutions(context, self._default_value)

    def describe(self) -> str:
        return f"{self.__class__.__name__}(name={describe(self._name)})"


class ForLoopIndex(ForEachVar):
    """``$(index NAME)``: the index of the for loop named NAME."""

    def __init__(self, name: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(name)

    @classmethod
    def parse(cls, data: Sequence[Any]) -> tuple[type[ForEachVar], dict[str, Any]]:
        if len(data) != 1:
            raise ValueError("ForLoopIndex substitution expects 1 argument")
        return cls, {"name": data[0]}


__all__ = ["ForEachVar", "ForLoopIndex"]
