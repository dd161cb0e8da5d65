"""``name:=value`` launch arguments from launch_test's command line."""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable


def parse_launch_arguments(launch_arguments: Iterable[str]) -> list[tuple[str, str]]:
    """``name:=value`` items -> (name, value) pairs, one per name (the last one wins).

    The value may itself hold ``:=``; an item without ``:=``, with no name, or ``name:=`` with
    no value is a RuntimeError naming it, as in launch_testing.
    """
    parsed: dict[str, str] = {}
    for argument in launch_arguments:
        name, separator, value = argument.partition(":=")
        if not separator or not name or not value:
            raise RuntimeError(
                f"malformed launch argument '{argument}', expected format '<name>:=<value>'"
            )
        parsed[name] = value
    return list(parsed.items())


__all__ = ["parse_launch_arguments"]
