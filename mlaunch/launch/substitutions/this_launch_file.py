"""``launch.substitutions.this_launch_file``: the path of the launch file being visited."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Substitution,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class ThisLaunchFile(Substitution):
    """The path of the launch file being resolved (``$(filename)``)."""

    def perform(self, context: LaunchContext) -> str:
        path = context.current_launch_file_path
        if path is None:
            raise SubstitutionFailure("ThisLaunchFile used outside of a launch file")
        return checked_local(context, "current_launch_file_path", path, "ThisLaunchFile")

    def describe(self) -> str:
        return "ThisLaunchFile()"


def checked_local(context: LaunchContext, key: str, value: str, what: str) -> str:
    """``value``, with mlaunch.launch.file_locals's warning when it is an included file's that
    PR #862's rule would not give (only then is that module loaded)."""
    if "mlaunch_own_file_locals" not in getattr(context, "_locals", ()):
        return value
    from mlaunch.launch.file_locals import checked

    return checked(context, key, value, what)
