"""``launch.substitutions.local_substitution``: an expression over the context's locals."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Substitution,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class LocalSubstitution(Substitution):
    """An attribute path in the context locals, e.g. ``event.returncode`` inside a handler."""

    def __init__(self, expression: str, description: str | None = None) -> None:
        self.expression = expression
        self.description = description

    def perform(self, context: LaunchContext) -> str:
        # launch evaluates the expression against the locals (``event.cmd[1]``, ``event.text``).
        try:
            value = eval(f"_locals.{self.expression}", {}, {"_locals": context.locals})
        except Exception as e:
            raise SubstitutionFailure(
                f"LocalSubstitution {self.expression!r} failed here: {type(e).__name__}: {e}"
                " (it is only valid where that local is defined, e.g. in an event handler)"
            )
        return str(value)

    def describe(self) -> str:
        return self.description or f"LocalVar({self.expression!r})"
