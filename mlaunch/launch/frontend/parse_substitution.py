"""``launch.frontend.parse_substitution``: a markup value to a list of substitutions.

The scanner is mlaunch's (``mlaunch.launch.frontend.template``, the one the readers use), so a
value reads the same from Python as in a launch file; plain text comes back as
TextSubstitution, as upstream returns it.
"""

from __future__ import annotations

import re

from mlaunch.launch.frontend.template import parse_template
from mlaunch.launch.substitution import Substitution, TextSubstitution

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Any

_ESCAPED = re.compile(r"\\(.)")


def replace_escaped_characters(data: str) -> str:
    """``data`` with each backslash escape replaced by the character it escapes."""
    return _ESCAPED.sub(r"\1", data)


def parse_substitution(string_value: str) -> list[Substitution]:
    """The substitutions of ``string_value`` (text, ``$(name args)``, nested and quoted)."""
    return [
        TextSubstitution(text=p) if isinstance(p, str) else p for p in parse_template(string_value)
    ]


def parse_if_substitutions(value: Any, parse: Any = None) -> Any:
    """A str with substitutions as a list of them, plain text as the str, any other scalar as
    it is; a list item by item. A list that mixes value types is a ValueError.

    ``parse`` reads one str (default ``parse_substitution``; a parser passes its own).
    """
    parse = parse or parse_substitution
    kinds: set[type] = set()

    def one(item: Any) -> Any:
        if isinstance(item, str):
            output = parse(item)
            if len(output) == 1 and isinstance(output[0], TextSubstitution):
                kinds.add(str)
                return output[0].text
            return output
        kinds.add(type(item))
        return item

    output = [one(x) for x in value] if isinstance(value, list) else one(value)
    if len(kinds) > 1:
        raise ValueError("The result is a non-uniform list")
    return output


__all__ = ["parse_if_substitutions", "parse_substitution", "replace_escaped_characters"]
