"""Matching expected text (a string, a regex, or a sequence of them in order) in output."""

from __future__ import annotations

import os
import re
from collections.abc import Iterable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    Match = Callable[..., "tuple[int, int] | None"]

# CSI sequences (colours, cursor moves) and the two-byte escapes terminals understand.
_ANSI = re.compile(r"\x1b\[[0-?]*[ -/]*[@-~]|\x1b[@-Z\\-_]")


def remove_ansi_escape_sequences(text: str) -> str:
    return _ANSI.sub("", text)


def normalize_lineseps(text: str) -> str:
    r"""Every line ending as ``\n`` (a pty gives ``\r\n``)."""
    return text.replace(os.linesep, "\n").replace("\r\n", "\n")


def _is_pattern(value: Any) -> bool:
    return hasattr(value, "search") and hasattr(value, "match")


def build_text_match(expected: Any, *, strict: bool = False) -> Match:
    """``match(text, start=0) -> (start, end) | None`` for ``expected`` in ``text``.

    ``strict``: the expectation must cover the text from ``start`` exactly (a string equal to
    the rest, a regex matching at ``start``, a sequence whose parts follow each other at once).
    """
    if isinstance(expected, str):

        def match_str(text: str, start: int = 0) -> tuple[int, int] | None:
            text = normalize_lineseps(text)
            if strict:
                return (start, len(text)) if text[start:] == expected else None
            found = text.find(expected, start)
            return None if found < 0 else (found, found + len(expected))

        return match_str
    if _is_pattern(expected):

        def match_regex(text: str, start: int = 0) -> tuple[int, int] | None:
            text = normalize_lineseps(text)
            m = expected.match(text, start) if strict else expected.search(text, start)
            return None if m is None else (m.start(), m.end())

        return match_regex
    if isinstance(expected, Iterable):
        return _sequence_match([build_text_match(e) for e in expected], strict, normalize=True)
    raise ValueError(f"expected text must be a str, a regex or a list of them, not {expected!r}")


def build_line_match(expected: Any, *, strict: bool = False) -> Match:
    """``match(lines, start=0) -> (first, end) | None``: line-wise, as build_text_match."""
    if isinstance(expected, str) or _is_pattern(expected):
        if isinstance(expected, str):

            def hit(line: str) -> bool:
                return (expected == line) if strict else (expected in line)
        else:

            def hit(line: str) -> bool:
                return bool(expected.match(line))

        def match_line(lines: list[str], start: int = 0) -> tuple[int, int] | None:
            rest = lines[start:]
            if strict:
                return (start, len(lines)) if all(hit(line) for line in rest) else None
            for i, line in enumerate(rest, start):
                if hit(line):
                    return i, i + 1
            return None

        return match_line
    if isinstance(expected, Iterable):
        return _sequence_match([build_line_match(e) for e in expected], strict, normalize=False)
    raise ValueError(f"expected lines must be a str, a regex or a list of them, not {expected!r}")


def _sequence_match(parts: list[Match], strict: bool, *, normalize: bool) -> Match:
    """Each part found after the previous one (right after it, when strict)."""
    if not parts:
        raise ValueError("an expected sequence needs at least one item")

    def match_all(actual: Any, start: int = 0) -> tuple[int, int] | None:
        if normalize:
            actual = normalize_lineseps(actual)
        first = None
        end = start
        for part in parts:
            found = part(actual, end)
            if found is None or (strict and found[0] != end):
                return None
            if first is None:
                first = found[0]
            end = found[1]
        return (start if first is None else first), end

    return match_all
