"""``perform_substitutions``: substitutions performed with a context and joined."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any


def perform_substitutions(context: Any, subs: Iterable[Any]) -> str:
    """Each substitution of ``subs`` performed through ``context.perform_substitution``,
    concatenated.

    As upstream's, ``subs`` must be an iterable of substitutions: something that is not
    iterable is a TypeError, an item that is no substitution (text, a number, a nested list)
    an AttributeError. Code that has text or a mixed list normalizes it first
    (``normalize_to_list_of_substitutions``).
    """
    return "".join(context.perform_substitution(_substitution(sub)) for sub in subs)


def _substitution(sub: Any) -> Any:
    if not callable(getattr(sub, "perform", None)):
        raise AttributeError(
            f"perform_substitutions takes substitutions; got {type(sub).__name__} {sub!r:.60},"
            " which has no 'perform' (normalize_to_list_of_substitutions turns text into one)"
        )
    return sub
