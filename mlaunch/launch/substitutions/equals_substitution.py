"""``launch.substitutions.equals_substitution``: whether two values are equal, as launch compares
them (numbers as numbers, booleans as booleans).
"""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Substitution,
    TextSubstitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch.substitutions.boolean_substitution import bool_text

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import Subs


def _equal(left: str, right: str) -> bool:
    """Bool-aware, then float-aware, else textual comparison (EqualsSubstitution's rule)."""
    bools = {"true": True, "false": False}
    lb, rb = bools.get(left.strip().lower()), bools.get(right.strip().lower())
    if lb is not None or rb is not None:
        if lb is None and left.strip() in ("0", "1"):
            lb = left.strip() == "1"
        if rb is None and right.strip() in ("0", "1"):
            rb = right.strip() == "1"
        if lb is not None and rb is not None:
            return lb == rb
    import math

    try:
        return math.isclose(float(left), float(right))
    except ValueError:
        return left == right


def _equals_operand(value: Any) -> Subs:
    if value is None:
        return (TextSubstitution(text=""),)
    if isinstance(value, bool):
        return (TextSubstitution(text=bool_text(value)),)
    return normalize(value)


class EqualsSubstitution(Substitution):
    def __init__(self, left: Any, right: Any) -> None:
        self.left = _equals_operand(left)
        self.right = _equals_operand(right)

    def perform(self, context: LaunchContext) -> str:
        left = perform_substitutions(context, self.left)
        right = perform_substitutions(context, self.right)
        return bool_text(_equal(left, right))

    def describe(self) -> str:
        return f"Equals({describe(self.left)}, {describe(self.right)})"
