"""``perform_substitutions``: substitutions performed with a context and joined."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any


def perform_substitutions(context: Any, subs: Iterable[Any]) -> str:
    """Each substitution performed through ``context.perform_substitution``, concatenated."""
    return "".join(context.perform_substitution(sub) for sub in subs)
