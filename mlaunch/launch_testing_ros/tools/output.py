"""``launch_testing_ros.tools.output``: launch_testing's output filter, plus the lines an RMW
implementation prints on its own (listed in the ament index as ``rmw_output_prefixes`` and
``rmw_output_patterns`` resources of that implementation)."""

from __future__ import annotations

from mlaunch.launch_testing.tools.output import (
    basic_output_filter as launch_testing_filter,
)
from mlaunch.launch_testing.tools.output import (
    get_default_filtered_patterns,
    get_default_filtered_prefixes,
    registered_rmw_filters,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable


def get_rmw_output_filter(rmw_implementation: str, filter_type: str) -> list[str]:
    """The ``filter_type`` ('prefixes' or 'patterns') lines ``rmw_implementation`` registered
    in the ament index, one filter a line; none when it registered none."""
    return registered_rmw_filters(rmw_implementation, filter_type)


def basic_output_filter(
    filtered_prefixes: list[str] | None = None,
    filtered_patterns: list[str] | None = None,
    filtered_rmw_implementation: str | None = None,
) -> Callable[[str], str]:
    """launch_testing's basic_output_filter, also dropping the lines of
    ``filtered_rmw_implementation`` (e.g. 'rmw_fastrtps_cpp') when given."""
    prefixes = get_default_filtered_prefixes() if filtered_prefixes is None else filtered_prefixes
    patterns = get_default_filtered_patterns() if filtered_patterns is None else filtered_patterns
    if filtered_rmw_implementation:
        prefixes = prefixes + get_rmw_output_filter(filtered_rmw_implementation, "prefixes")
        patterns = patterns + get_rmw_output_filter(filtered_rmw_implementation, "patterns")
    return launch_testing_filter(prefixes, patterns)


__all__ = ["basic_output_filter", "get_rmw_output_filter"]
