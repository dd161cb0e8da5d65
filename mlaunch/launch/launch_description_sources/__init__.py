"""Where an included launch description comes from: a path (any format) or a built description."""

from __future__ import annotations

from mlaunch.launch.substitutions import describe, normalize, perform_substitutions

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

    def try_get_launch_description_without_context(self) -> Any:
        """The description when it was given (a file needs a context to be located)."""
        return self.launch_description


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


class PythonLaunchDescriptionSource(AnyLaunchDescriptionSource):
    format_hint = "python"
    method_text = "interpreted python launch file"


class FrontendLaunchDescriptionSource(AnyLaunchDescriptionSource):
    method_text = "interpreted frontend launch file"


class XMLLaunchDescriptionSource(AnyLaunchDescriptionSource):
    format_hint = "xml"
    method_text = "interpreted XML launch file"


class YAMLLaunchDescriptionSource(AnyLaunchDescriptionSource):
    format_hint = "yaml"
    method_text = "interpreted YAML launch file"


def source_for(value: Any) -> LaunchDescriptionSource:
    """IncludeLaunchDescription also takes a bare path or a LaunchDescription."""
    from mlaunch.launch.launch_description import LaunchDescription

    if isinstance(value, LaunchDescription):
        return LaunchDescriptionSource(launch_description=value)
    return AnyLaunchDescriptionSource(value)


_LOADERS = {
    "InvalidPythonLaunchFileError",
    "get_launch_description_from_python_launch_file",
    "load_python_launch_file_as_module",
}


def __getattr__(name: str) -> Any:
    # The loaders import importlib's file machinery: only when a caller asks for them.
    if name in _LOADERS:
        from mlaunch.launch.launch_description_sources import python_launch_file_utilities

        return getattr(python_launch_file_utilities, name)
    if name == "InvalidLaunchFileError":
        from mlaunch.launch.invalid_launch_file_error import InvalidLaunchFileError

        return InvalidLaunchFileError
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "AnyLaunchDescriptionSource",
    "FrontendLaunchDescriptionSource",
    "LaunchDescriptionSource",
    "PythonLaunchDescriptionSource",
    "XMLLaunchDescriptionSource",
    "YAMLLaunchDescriptionSource",
]
