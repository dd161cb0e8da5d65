"""``launch_test --show-args``: the launch arguments a test description declares."""

from __future__ import annotations

import os
import sys

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


def print_arguments_of_launch_description(
    *, launch_description: Any, path: str | None = None
) -> None:
    """Print every argument the description declares (with those of the files it includes when
    their paths resolve without running anything), or 'No arguments.'.

    ``path`` is the test file, for the descriptions it includes by a relative path.
    """
    from mlaunch.resolve.describe import format_arguments
    from mlaunch.resolve.resolver import collect_arguments

    infos = collect_arguments(launch_description, path=path, arguments={}, environ=os.environ)
    sys.stdout.write(format_arguments(infos))


__all__ = ["print_arguments_of_launch_description"]
