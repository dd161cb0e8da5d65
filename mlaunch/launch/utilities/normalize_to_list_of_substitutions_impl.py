"""``normalize_to_list_of_substitutions``: text and substitutions as a list of substitutions."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from mlaunch.launch.substitution import Substitution, TextSubstitution


def _one(item: Any) -> Substitution:
    if isinstance(item, Substitution):
        return item
    if isinstance(item, str):
        return TextSubstitution(text=item)
    raise TypeError(
        f"Failed to normalize given item of type '{type(item)}', when only "
        "'str' or 'launch.Substitution' were expected."
    )


def normalize_to_list_of_substitutions(subs: Any) -> list[Substitution]:
    """A str, a Substitution, or an iterable of them, as a list (launch refuses anything else)."""
    if isinstance(subs, str):
        return [TextSubstitution(text=subs)]
    if isinstance(subs, Substitution):
        return [subs]
    if not isinstance(subs, Iterable):
        raise TypeError(f"expected a str, a Substitution or a list of them, got {subs!r}")
    return [_one(item) for item in subs]
