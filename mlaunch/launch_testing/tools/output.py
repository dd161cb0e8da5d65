"""``launch_testing.tools.output``: filter a process's output and match it against expectations.

An expectation is a text (a string, a regex, or a sequence of them in order) or lines; see
``launch_testing.tools.text`` for how each matches.
"""

from __future__ import annotations

import os
import re

from mlaunch.launch_testing.tools.text import (
    build_line_match,
    build_text_match,
    remove_ansi_escape_sequences,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def get_default_filtered_prefixes() -> list[str]:
    """The line prefixes basic_output_filter drops unless told: ``pid`` and ``rc``."""
    return ["pid", "rc"]


def get_default_filtered_patterns() -> list[str]:
    """The line patterns basic_output_filter drops unless told: none."""
    return []


RMW_FILTER_TYPES = ("prefixes", "patterns")


def registered_rmw_filters(rmw_implementation: str, filter_type: str) -> list[str]:
    """The lines of output filters ``rmw_implementation`` registers in the ament index as its
    ``rmw_output_prefixes`` or ``rmw_output_patterns`` resource (``filter_type``), one a line;
    none when it registers none (launch_testing_ros and launch_testing.legacy read them)."""
    if filter_type not in RMW_FILTER_TYPES:
        raise TypeError(
            f'Unsupported filter_type "{filter_type}". Supported types: {list(RMW_FILTER_TYPES)}'
        )
    from mlaunch.ros import ament_index

    resource_type = "rmw_output_" + filter_type
    if not ament_index.has_resource(resource_type, rmw_implementation):
        return []
    content, _ = ament_index.get_resource(resource_type, rmw_implementation)
    return content.splitlines()


def basic_output_filter(
    filtered_prefixes: list[str] | None = None, filtered_patterns: list[str] | None = None
) -> Callable[[str], str]:
    """A filter dropping lines that start with a prefix (``pid``, ``rc`` by default) or match."""
    if filtered_prefixes is None:
        filtered_prefixes = get_default_filtered_prefixes()
    if filtered_patterns is None:
        filtered_patterns = get_default_filtered_patterns()
    prefixes = tuple(filtered_prefixes)
    patterns = [re.compile(p) for p in filtered_patterns]

    def keep(line: str) -> bool:
        return not line.startswith(prefixes) and not any(p.match(line) for p in patterns)

    def output_filter(output: str) -> str:
        return "".join(line for line in output.splitlines(keepends=True) if keep(line))

    return output_filter


def expected_output_from_file(path: str, encoding: str | None = None) -> list[Any]:
    """The lines of ``path.txt``, or the regexes of ``path.regex``."""
    for suffix, make in ((".txt", str), (".regex", re.compile)):
        if os.path.isfile(path + suffix):
            with open(path + suffix, encoding=encoding) as f:
                return [make(line) for line in f.read().splitlines()]
    raise RuntimeError(f"could not find output check file: {path}.txt or {path}.regex")


def expect_output(
    text: str | None = None,
    *,
    lines: list[str] | None = None,
    expected_text: Any = None,
    expected_lines: Any = None,
    strip_ansi_escape_sequences: bool = True,
    strict: bool = False,
) -> bool:
    """Whether the text (or lines) given matches the text (or lines) expected."""
    if (text is None) == (lines is None):
        raise ValueError("Either lines or text, but not both, must be specified")
    if (expected_text is None) == (expected_lines is None):
        raise ValueError("Either expected lines or text, but not both, must be specified")
    if expected_text is not None:
        actual = text if text is not None else "\n".join(lines or [])
        if strip_ansi_escape_sequences:
            actual = remove_ansi_escape_sequences(actual)
        return build_text_match(expected_text, strict=strict)(actual) is not None
    actual_lines = lines if lines is not None else (text or "").splitlines()
    if strip_ansi_escape_sequences:
        actual_lines = [remove_ansi_escape_sequences(line) for line in actual_lines]
    return build_line_match(expected_lines, strict=strict)(actual_lines) is not None


__all__ = [
    "basic_output_filter",
    "expect_output",
    "expected_output_from_file",
    "get_default_filtered_patterns",
    "get_default_filtered_prefixes",
]
