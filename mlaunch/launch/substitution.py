"""The Substitution base class, the values launch accepts in its place, and how they are
normalized, performed and described (ROS 2's ``launch.substitution`` and
``launch.some_substitutions_type``). The substitutions themselves are mlaunch.launch.substitutions'.

A substitution is data until ``perform(context)`` is called while resolving; ``describe()`` shows
it unresolved (``--print`` of deferred actions, ``--show-args`` defaults).
"""

from __future__ import annotations

import os
from collections.abc import Iterable

# pathlib is not imported: it costs milliseconds at start-up, and os.PathLike covers Path.
Path = os.PathLike

# typing (~4 ms) and subprocess (~3 ms, with selectors and threading) are not imported at start-up:
# annotations are strings, and only Command() runs a program. mypy treats this name as
# typing.TYPE_CHECKING.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class Substitution:
    """Base class: something that becomes a string when the launch is resolved."""

    def perform(self, context: LaunchContext) -> str:
        raise NotImplementedError

    def describe(self) -> str:
        return type(self).__name__ + "(...)"

    def __repr__(self) -> str:
        return self.describe()


# What ROS 2's launch files annotate arguments with; a union of classes, no typing needed.
SomeSubstitutionsType = (
    str | os.PathLike[str] | Substitution | Iterable[str | os.PathLike[str] | Substitution]
)
SomeSubstitutionsType_types_tuple = (str, Path, Substitution)
Subs = tuple[Substitution, ...]


def normalize(value: Any) -> Subs:
    """Turn a str, Path, Substitution or iterable of those into a tuple of substitutions.

    Lists concatenate when performed, as in ROS 2 (``['a', LaunchConfiguration('b')]`` is one
    string).
    """
    if isinstance(value, Substitution):
        return (value,)
    if isinstance(value, str):
        return (TextSubstitution(text=value),)
    if type(value) is list or type(value) is tuple:
        # The usual case (a cmd, a list of text and substitutions), taken before the checks
        # against os.PathLike and Iterable below: those are ABCs, whose isinstance costs about
        # a microsecond each time, and a plain list or tuple is never path-like.
        out: list[Substitution] = []
        for item in value:
            if isinstance(item, Substitution):
                out.append(item)
            elif isinstance(item, str):
                out.append(TextSubstitution(text=item))
            else:
                out.extend(normalize(item))
        return tuple(out)
    if isinstance(value, os.PathLike):
        return (TextSubstitution(text=os.fspath(value)),)
    if isinstance(value, (int, float, bool)):
        return (TextSubstitution(text=str(value)),)
    if isinstance(value, Iterable):
        items: list[Substitution] = []
        for item in value:
            items.extend(normalize(item))
        return tuple(items)
    raise TypeError(
        f"expected a str, a Substitution or a list of them, got {type(value).__name__}: {value!r}"
    )


def is_substitution_like(value: Any) -> bool:
    if isinstance(value, (str, Path, Substitution)):
        return True
    return isinstance(value, (list, tuple)) and all(
        isinstance(v, (str, Path, Substitution)) for v in value
    )


# How deep substitutions may nest in one another ($(env X $(env Y ...)), or the same built in a
# loop in Python): real files nest a handful; 200 levels cost ~600 interpreter frames, which fits
# beside the deepest launch tree (mlaunch.frontends.limits), where 20,000 ended in a RecursionError.
SUBSTITUTION_DEPTH_LIMIT = 200
_depth = [0]  # substitutions being performed inside one another now (resolving is one thread)


def perform_substitutions(context: LaunchContext, subs: Sequence[Substitution]) -> str:
    """Perform each substitution and concatenate the results."""
    if _depth[0] >= SUBSTITUTION_DEPTH_LIMIT:
        from mlaunch.plan.errors import SubstitutionFailure  # error path only

        raise SubstitutionFailure(
            f"substitutions nest deeper than {SUBSTITUTION_DEPTH_LIMIT} levels, mlaunch's limit"
            f" (the innermost: {subs[0].describe()[:60] if subs else '?'}); flatten them"
        )
    _depth[0] += 1
    try:
        if len(subs) == 1:
            return subs[0].perform(context)
        return "".join(s.perform(context) for s in subs)
    finally:
        _depth[0] -= 1


def perform(context: LaunchContext, value: Any) -> str:
    """Perform any SomeSubstitutionsType value (str, Substitution, list) to a string."""
    if isinstance(value, str):
        return value
    return perform_substitutions(context, normalize(value))


_describing = [0]  # values being described inside one another now


def describe(value: Any) -> str:
    """Describe an unresolved value: text in quotes, substitutions by their describe().

    Past ``SUBSTITUTION_DEPTH_LIMIT`` levels the rest is ``...``: a description is for people,
    and one built 20,000 deep in a Python loop must not end in a RecursionError before the
    performing says where it is too deep.
    """
    if _describing[0] >= SUBSTITUTION_DEPTH_LIMIT:
        return "..."
    _describing[0] += 1
    try:
        subs = normalize(value)
        return " + ".join(s.describe() for s in subs) if subs else "''"
    finally:
        _describing[0] -= 1


class TextSubstitution(Substitution):
    """Literal text."""

    def __init__(self, *, text: str) -> None:
        self.text = str(text)

    def perform(self, context: LaunchContext) -> str:
        return self.text

    def describe(self) -> str:
        return repr(self.text)


__all__ = [
    "SomeSubstitutionsType",
    "SomeSubstitutionsType_types_tuple",
    "Substitution",
    "TextSubstitution",
    "describe",
    "is_substitution_like",
    "normalize",
    "perform",
    "perform_substitutions",
]
