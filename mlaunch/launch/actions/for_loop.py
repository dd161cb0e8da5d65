"""``launch.actions.for_loop``: ForEach and ForLoop, newer than Jazzy (launch 3.8, Kilted).

ForEach splits its values at ``;``, reads each piece as YAML and calls ``function`` with that
mapping's items as keyword arguments, once per piece; ForLoop calls it with ``i`` from 0 to
``length`` (exclusive). From XML and YAML (``<for_each values=...>``, ``<for len=... name=...>``)
the children are copied for each iteration and see the iteration's values through
``$(for-var NAME [default])`` and ``$(index NAME)``, which read the context's locals (pushed
and popped around each iteration, so they do not leak). ``--check`` says each is newer than
Jazzy; mlaunch runs them with Jazzy's semantics for everything else.
"""

from __future__ import annotations

import copy

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import normalize, perform_substitutions
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import Log

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class ForEach(Action):
    """Entities from ``function(**values)`` for each ``;``-separated YAML mapping of values."""

    SEPARATOR = ";"

    def __init__(
        self,
        input_values: SomeSubstitutionsType,
        *,
        function: Callable[..., list[Any] | None],
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self._input_values = normalize(input_values)
        self._function = function

    @property
    def input_values(self) -> Sequence[Any]:
        return self._input_values

    @property
    def function(self) -> Callable[..., list[Any] | None]:
        return self._function

    def describe(self) -> str:
        return f"ForEach(input_values={self._input_values!r}, function={self._function!r})"

    def execute(self, context: LaunchContext) -> list[Any]:
        text = perform_substitutions(context, self._input_values)
        pieces = [p.strip() for p in text.strip().split(self.SEPARATOR) if p]
        if not pieces:
            context.planner.add(
                Log(
                    origin=self.origin, level="WARNING", message="no input values: will not iterate"
                )
            )
        entities: list[Any] = []
        for piece in pieces:
            values = _mapping(piece, self.origin)
            if values is None:  # an empty piece: launch skips it too
                continue
            made = context.planner.call_user(self._function, **values)
            entities.extend(made or [])
        return entities

    @classmethod
    def iteration_entities(cls, children: list[Any], values: Mapping[str, Any]) -> list[Any]:
        """One iteration of a frontend's loop: a copy of ``children`` that sees ``values``
        through $(for-var) and $(index), in locals of its own."""
        from mlaunch.launch.actions.opaque_function import OpaqueFunction
        from mlaunch.launch.substitutions.for_loop_var import ForEachVar

        local = {ForEachVar.get_local_arg_name(k): str(v) for k, v in values.items()}
        return [
            OpaqueFunction(function=_push_locals),
            OpaqueFunction(function=_extend_locals, args=(local,)),
            *copy.deepcopy(children),
            OpaqueFunction(function=_pop_locals),
        ]


class ForLoop(Action):
    """Entities from ``function(i)`` for ``i`` in ``range(length)``."""

    def __init__(
        self,
        length: SomeSubstitutionsType,
        *,
        function: Callable[..., list[Any] | None],
        name: str | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self._length = normalize(length)
        self._function = function
        self._name = name

    @property
    def length(self) -> Sequence[Any]:
        return self._length

    @property
    def function(self) -> Callable[..., list[Any] | None]:
        return self._function

    @property
    def name(self) -> str | None:
        return self._name

    def describe(self) -> str:
        return f"ForLoop(length={self._length!r}, name={self._name!r})"

    def execute(self, context: LaunchContext) -> list[Any]:
        text = perform_substitutions(context, self._length)
        try:
            length = int(text)
        except ValueError:
            raise LaunchFileError(
                f"ForLoop's length is {text!r}; it must be a whole number (int())",
                where=self.origin,
            ) from None
        values = ForEach.SEPARATOR.join(f"{{i: {i}}}" for i in range(length))
        each = ForEach(values, function=self._function)
        each.origin = self.origin
        return [each]


def _mapping(piece: str, origin: str) -> dict[str, Any] | None:
    """One iteration's values: a YAML mapping (None for an empty piece)."""
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        values = load_yaml(piece, origin)
    except yaml.YAMLError as e:
        raise LaunchFileError(f"ForEach values {piece!r} are not YAML: {e}", where=origin) from e
    if values is not None and not isinstance(values, dict):
        raise LaunchFileError(
            f"ForEach values {piece!r} are not a YAML mapping; write them as"
            " {name: value, ...} pieces separated by ';'",
            where=origin,
        )
    return values


def _push_locals(context: LaunchContext) -> None:
    context._push_locals()


def _extend_locals(context: LaunchContext, values: Mapping[str, str]) -> None:
    context.extend_locals(values)


def _pop_locals(context: LaunchContext) -> None:
    context._pop_locals()


__all__ = ["ForEach", "ForLoop"]
