"""``launch.event_handlers.event_named``: a matcher of the events with a name."""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def event_named(name: str) -> Callable[[Any], bool]:
    """A matcher of the events called ``name``."""
    return lambda event: getattr(event, "name", None) == name
