"""``launch.launch_description_sources.any_launch_description_source``: a launch file of any
format, chosen by its suffix.
"""

from __future__ import annotations

from mlaunch.launch.launch_description_source import LaunchDescriptionSource

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class AnyLaunchDescriptionSource(LaunchDescriptionSource):
    """A launch file of any format, chosen by its suffix."""

    # How the description is made, as upstream's sources say it (``method``).
    method_text = "interpreted launch file"

    def __init__(self, launch_file_path: Any) -> None:
        super().__init__(None, launch_file_path, self.method_text)

    def get_launch_description(self, context: LaunchContext) -> Any:
        """The file's description, loaded once by the context's planner (a standalone one for a
        context-like object that has none)."""
        self._expand(context)
        if self.launch_description is None:
            from mlaunch.launch.planning import planner_of

            self.launch_description = planner_of(context).load_source(self, "")
        return self.launch_description

    def try_get_launch_description_without_context(self) -> Any:
        """The description given, or the file's loaded with a fresh context (kept apart from
        what a run loads); None when that fails, e.g. its path needs a launch argument."""
        if self.launch_description is not None:
            return self.launch_description
        from mlaunch.launch.launch_context import LaunchContext

        try:
            return LaunchContext().planner.load_source(self, "")
        except Exception:  # introspection only: the include itself will say what is wrong
            return None


def source_for(value: Any) -> LaunchDescriptionSource:
    """IncludeLaunchDescription also takes a bare path or a LaunchDescription."""
    from mlaunch.launch.launch_description import LaunchDescription

    if isinstance(value, LaunchDescription):
        return LaunchDescriptionSource(launch_description=value)
    return AnyLaunchDescriptionSource(value)
