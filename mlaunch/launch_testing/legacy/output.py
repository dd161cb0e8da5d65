"""``launch_testing.legacy.output``: the output tests LaunchTestService.add_output_test takes,
and a line filter, all on bytes.

An output test is ``(buffer, collate(buffer, more) -> buffer, match(buffer, expectation) ->
bool, expectations)``: expected lines (each found within one line) or regexes (searched in the
whole output).
"""

from __future__ import annotations

import io
import os
import re

from mlaunch.launch_testing.tools.output import registered_rmw_filters

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    OutputTest = tuple[io.BytesIO, Callable[..., io.BytesIO], Callable[..., bool], list[Any]]


def get_default_filtered_prefixes() -> list[bytes]:
    return [b"pid", b"rc"]


def get_default_filtered_patterns() -> list[bytes]:
    return []


def get_rmw_output_filter(rmw_implementation: str, filter_type: str) -> list[bytes]:
    """The ``filter_type`` ('prefixes' or 'patterns') lines ``rmw_implementation`` registered
    in the ament index (``rmw_output_<filter_type>``), as bytes."""
    return [line.encode() for line in registered_rmw_filters(rmw_implementation, filter_type)]


def create_output_lines_filter(
    filtered_prefixes: list[bytes] | None = None,
    filtered_patterns: list[bytes] | None = None,
    filtered_rmw_implementation: str | None = None,
) -> Callable[[bytes], bytes]:
    """A filter of output bytes dropping lines that start with a prefix (``pid``, ``rc`` by
    default) or match a pattern, and those the RMW implementation registered."""
    prefixes = list(filtered_prefixes or get_default_filtered_prefixes())
    patterns = list(filtered_patterns or get_default_filtered_patterns())
    if filtered_rmw_implementation:
        prefixes += get_rmw_output_filter(filtered_rmw_implementation, "prefixes")
        patterns += get_rmw_output_filter(filtered_rmw_implementation, "patterns")
    compiled = [re.compile(pattern) for pattern in patterns]
    separator = os.linesep.encode("ascii")

    def keep(line: bytes) -> bool:
        return not line.startswith(tuple(prefixes)) and not any(p.match(line) for p in compiled)

    def output_filter(output: bytes) -> bytes:
        kept = [line for line in output.splitlines() if keep(line)]
        if output.endswith(separator):
            kept.append(separator)
        return separator.join(kept)

    return output_filter


def create_output_lines_test(expected_lines: list[bytes]) -> OutputTest:
    """An output test passing once each expected line is found within a line of output."""

    def collate(output: io.BytesIO, more: bytes) -> io.BytesIO:
        output.write(more)
        return output

    def match(output: io.BytesIO, expected: bytes) -> bool:
        return any(expected in line for line in output.getvalue().splitlines())

    return io.BytesIO(), collate, match, expected_lines


def create_output_regex_test(expected_patterns: list[re.Pattern[bytes]]) -> OutputTest:
    """An output test passing once each regex is found in the output (lines joined by \\n)."""

    def collate(output: io.BytesIO, more: bytes) -> io.BytesIO:
        output.write(b"\n".join(more.splitlines()))
        return output

    def match(output: io.BytesIO, pattern: re.Pattern[bytes]) -> bool:
        return pattern.search(output.getvalue()) is not None

    return io.BytesIO(), collate, match, expected_patterns


def create_output_test_from_file(output_file: str) -> OutputTest:
    """The output test of ``output_file.txt`` (expected lines) or ``output_file.regex``."""
    if os.path.isfile(output_file + ".txt"):
        with open(output_file + ".txt", "rb") as f:
            return create_output_lines_test(f.read().splitlines())
    if os.path.isfile(output_file + ".regex"):
        with open(output_file + ".regex", "rb") as f:
            return create_output_regex_test([re.compile(line) for line in f.read().splitlines()])
    raise RuntimeError(f"could not find output check file: {output_file}")


__all__ = [
    "create_output_lines_filter",
    "create_output_lines_test",
    "create_output_regex_test",
    "create_output_test_from_file",
    "get_default_filtered_patterns",
    "get_default_filtered_prefixes",
    "get_rmw_output_filter",
]
