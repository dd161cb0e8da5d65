"""``launch.substitutions.launch_log_dir``: the log directory of this run."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    Substitution,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class LaunchLogDir(Substitution):
    """The log directory of this run (``$(log_dir)``)."""

    def perform(self, context: LaunchContext) -> str:
        if context.log_dir:
            return context.log_dir
        # A context no run made: launch.logging's folder, made on first use, as launch's.
        from mlaunch.launch.logging import launch_config

        return launch_config.log_dir

    def describe(self) -> str:
        return "LaunchLogDir()"
