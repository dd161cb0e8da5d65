"""Small readers the YAML/XML tag builders share: required values, pairs, dict keys."""

from __future__ import annotations

from collections.abc import Callable

from mlaunch.frontends.element import Element
from mlaunch.launch.frontend.template import Parts

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

    Builder = Callable[[Element], Any]
else:  # the same at run time, without typing.Any
    Builder = Callable[[Element], object]
Value = str | Parts


def finish_all(entities: list[Element]) -> None:
    """Check that each entity's attributes were all read."""
    for entity in entities:
        entity.finish()


def required_text(e: Element, name: str) -> Value:
    """The text of a required attribute (an error names the tag and attribute when missing)."""
    value = e.text(name, required=True)
    assert value is not None
    return value


def as_key(value: Value) -> Any:
    """A value usable as a dict key (a list of parts becomes a tuple)."""
    return value if isinstance(value, str) else tuple(value)


def pairs(entities: list[Element], first: str, second: str) -> list[tuple[Value, Value]]:
    """``<x first=.. second=..>`` sub-entities as (first, second) pairs, each checked."""
    out = []
    for sub in entities:
        out.append((required_text(sub, first), required_text(sub, second)))
        sub.finish()
    return out


def required_literal(e: Element, name: str) -> str:
    """A required attribute that must be plain text, without substitutions."""
    value = e.literal(name, required=True)
    assert value is not None
    return value
