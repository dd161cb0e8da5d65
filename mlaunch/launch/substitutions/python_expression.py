"""``launch.substitutions.python_expression``: the value of a Python expression."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class PythonExpression(Substitution):
    """The str() of a Python expression (``$(eval 'expr' [modules])``); math names are bare."""

    def __init__(self, expression: SomeSubstitutionsType, python_modules: Any = ("math",)) -> None:
        self.expression = normalize(expression)
        self.python_modules = python_modules

    def _modules(self, context: LaunchContext) -> list[str]:
        mods = self.python_modules
        if isinstance(mods, (str, Substitution)):
            text = perform(context, mods)
            return [m.strip() for m in text.split(",") if m.strip()]
        return [perform(context, m) for m in mods]

    def perform(self, context: LaunchContext) -> str:
        import importlib
        import math

        expression = perform_substitutions(context, self.expression)
        namespace: dict[str, Any] = {}
        for name in self._modules(context):
            try:
                module = importlib.import_module(name)
            except ImportError as e:
                raise SubstitutionFailure(f"PythonExpression cannot import {name!r}: {e}")
            namespace[name] = module
            if module is math:
                namespace.update({k: v for k, v in vars(math).items() if not k.startswith("_")})
        try:
            return str(eval(expression, {}, namespace))
        except Exception as e:
            message = f"Python expression {expression!r} failed: {type(e).__name__}: {e}"
            raise _failure_of(e, message) from e

    def describe(self) -> str:
        mods = self.python_modules
        listed = [mods] if isinstance(mods, (str, Substitution)) else list(mods)
        modules = ", ".join(describe(normalize(m)) for m in listed)
        return f"PythonExpr({describe(self.expression)}, [{modules}])"


def _failure_of(error: Exception, message: str) -> SubstitutionFailure:
    """A SubstitutionFailure that is also an instance of ``error``'s type: mlaunch reports it
    as one located line, and code written against launch still catches the NameError (or
    whatever the expression raised) that launch lets through."""
    try:
        both = type(type(error).__name__, (SubstitutionFailure, type(error)), {})
        failure: SubstitutionFailure = both(message)
    except TypeError:  # a type that cannot be combined (or built from one message)
        failure = SubstitutionFailure(message)
    return failure
