"""A command line written in a launch file (``cmd``, ``args``) split into argv items.

Shared by the readers' process tags and ``ExecuteProcess._parse_cmdline`` (upstream's helper
that parse methods of exposed tags call).
"""

from __future__ import annotations

from mlaunch.launch.frontend.template import Part, Parts
from mlaunch.launch.substitution import Substitution, TextSubstitution, normalize

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Any


def parse_cmdline(cmd: str, parser: Any) -> list[list[Substitution]]:
    """``cmd`` parsed with ``parser``'s substitutions and split; each item a list of
    substitutions (upstream's ``ExecuteProcess._parse_cmdline``)."""
    parts: Parts = [
        p.text if type(p) is TextSubstitution else p for p in parser.parse_substitution(cmd)
    ]
    return [list(normalize(item)) for item in split_parts(parts)]


def split_parts(parts: Parts) -> list[Any]:
    """Text and substitutions split into argv items, as ``split_command`` of the readers says:
    whitespace outside quotes separates, a substitution joins the item it touches; each item is
    a str, a Substitution or a list of both. ValueError for an unclosed quote."""
    args: list[Any] = []
    if parts and isinstance(parts[0], str) and not parts[0].strip():
        # ros2 launch's split ends an argument at every blank-only text, even before the
        # first one: a command line that is empty (``args=""``: Autoware's containers) or that
        # starts with blanks before a substitution starts with an empty argument.
        args.append("")
    current: list[Part] = []
    buf: list[str] = []
    in_token = False
    quote: str | None = None

    def flush() -> None:
        if buf:
            text = "".join(buf)
            buf.clear()
            if current and isinstance(current[-1], str):
                current[-1] += text
            else:
                current.append(text)

    for part in parts:
        if isinstance(part, Substitution):
            flush()
            current.append(part)
            in_token = True
            continue
        i, n = 0, len(part)
        while i < n:
            c = part[i]
            if quote == "'":
                if c == "'":
                    quote = None
                else:
                    buf.append(c)
            elif quote == '"':
                if c == '"':
                    quote = None
                elif c == "\\" and i + 1 < n and part[i + 1] in '"\\':
                    buf.append(part[i + 1])
                    i += 1
                else:
                    buf.append(c)
            elif c.isspace():
                if in_token:
                    flush()
                    args.append(current[0] if len(current) == 1 else list(current))
                    current.clear()
                    in_token = False
            elif c in "'\"":
                quote = c
                in_token = True
            elif c == "\\" and i + 1 < n:
                buf.append(part[i + 1])
                in_token = True
                i += 1
            else:
                buf.append(c)
                in_token = True
            i += 1
    if quote is not None:
        raise ValueError(f"the quote {quote} is not closed")
    if in_token:
        flush()
        args.append(current[0] if len(current) == 1 else (list(current) or ""))
    return args
