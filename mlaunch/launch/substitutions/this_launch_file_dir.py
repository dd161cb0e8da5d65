"""``launch.substitutions.this_launch_file_dir``: the folder of the launch file being visited."""

from __future__ import annotations

import os

from mlaunch.launch.substitution import (
    Substitution,
)
from mlaunch.launch.substitutions.this_launch_file import checked_local
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class ThisLaunchFileDir(Substitution):
    """The directory of the launch file being resolved (``$(dirname)``)."""

    def perform(self, context: LaunchContext) -> str:
        # The local launch sets with the file (a script may set it itself, as launch's tests do).
        directory = context.locals.get("current_launch_file_directory")
        if directory is not None:
            return checked_local(
                context, "current_launch_file_directory", str(directory), "ThisLaunchFileDir"
            )
        path = context.current_launch_file_path
        if path is None:
            raise SubstitutionFailure("ThisLaunchFileDir used outside of a launch file")
        return os.path.dirname(path)

    def describe(self) -> str:
        return "ThisLaunchFileDir()"
