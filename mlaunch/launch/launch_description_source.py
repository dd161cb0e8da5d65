"""``launch.launch_description_source``: ``LaunchDescriptionSource``, where an included launch
description comes from: a location, or a description given as such.
"""

from __future__ import annotations

from mlaunch.launch.substitution import describe, normalize, perform_substitutions

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class LaunchDescriptionSource:
    """A launch description given directly, or a location loaded when the include resolves."""

    format_hint: str | None = None

    def __init__(
        self,
        launch_description: Any = None,
        location: Any = "<string>",
        method: str = "unspecified mechanism from a script",
    ) -> None:
        self.launch_description = launch_description
        self._location = normalize(location)
        self._expanded_location: str | None = None
        self.method = method

    @property
    def location(self) -> str:
        """Where the description comes from: as written until it was got with a context, then
        the location that context gave, as upstream's."""
        if self._expanded_location is not None:
            return self._expanded_location
        return " + ".join(getattr(s, "text", None) or s.describe() for s in self._location)

    def get_launch_file_location(self, context: LaunchContext) -> str | None:
        if self.launch_description is not None:
            return None
        import os

        return os.path.abspath(perform_substitutions(context, self._location))

    def describe(self) -> str:
        return describe(self._location)

    def get_launch_description(self, context: LaunchContext) -> Any:
        """The description given; RuntimeError without one, as upstream's base class (the
        sources of a file load it: AnyLaunchDescriptionSource)."""
        self._expand(context)
        if self.launch_description is None:
            raise RuntimeError(
                f"{type(self).__name__}.get_launch_description(): no launch description was"
                " given, and this kind of source loads no file"
            )
        return self.launch_description

    def _expand(self, context: LaunchContext) -> None:
        if self._expanded_location is None:
            self._expanded_location = perform_substitutions(context, self._location)

    def expand_location(self, context: LaunchContext) -> str:
        """The location performed with ``context`` now (what an include visited there points
        the locals at); ``location`` reads it back from then on."""
        self._expanded_location = perform_substitutions(context, self._location)
        return self._expanded_location

    @staticmethod
    def load_file(path: str) -> Any:
        """The description of the launch file at ``path``, loaded as a context that no run plans
        loads it (a run's planner loads with mlaunch's readers): a Python file by its
        ``generate_launch_description``, any other format by ``launch.frontend``."""
        if path.endswith(".py"):
            from mlaunch.launch.launch_description_sources.python_launch_file_utilities import (
                get_launch_description_from_python_launch_file,
            )

            return get_launch_description_from_python_launch_file(path)
        # XML, YAML (or a package's format): launch.frontend finds the implementation.
        from mlaunch.launch.frontend.parser import Parser

        root, parser = Parser.load(path)
        return parser.parse_description(root)

    def try_get_launch_description_without_context(self) -> Any:
        """The description when it was given (a file needs a context to be located)."""
        return self.launch_description
