"""``launch.frontend.Parser``: picks the markup implementation for a file and builds a
LaunchDescription from its root entity.

Implementations are found as upstream finds them, in an explicit table filled from entry points:
upstream's group ``launch.frontend.parser`` (a third-party format) and mlaunch's own group
``mlaunch.frontend.parser`` (its XML and YAML readers). mlaunch registers under its own group so
that a real ROS 2 installation sharing the Python environment never loads mlaunch's parsers.
Third-party tags and substitutions come from ``launch.frontend.launch_extension`` entry points
(loaded once, on the first tag or substitution the built-in tables do not have).
"""

from __future__ import annotations

import os
import traceback
import warnings

from mlaunch.launch.frontend.entity import Entity
from mlaunch.launch.frontend.expose import instantiate_action
from mlaunch.launch.frontend.parse_substitution import (
    parse_if_substitutions,
    parse_substitution,
    replace_escaped_characters,
)
from mlaunch.launch.invalid_launch_file_error import InvalidLaunchFileError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Any, TextIO

    from mlaunch.launch.action import Action
    from mlaunch.launch.launch_description import LaunchDescription
    from mlaunch.launch.substitution import Substitution

PARSER_GROUPS = ("launch.frontend.parser", "mlaunch.frontend.parser")
EXTENSION_GROUP = "launch.frontend.launch_extension"


class InvalidFrontendLaunchFileError(InvalidLaunchFileError):
    """No markup implementation could read the file."""


def __getattr__(name: str) -> Any:
    """``importlib_metadata`` (upstream's module name for it), imported on first use: it costs
    ~20-40 ms (email, zipfile, csv...) and a file whose tags are all built in never reads an
    entry point (a Python launch file that imports launch_xml to include XML, as Autoware's do)."""
    if name == "importlib_metadata":
        import importlib.metadata

        globals()[name] = importlib.metadata
        return importlib.metadata
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _entry_points(group: str) -> Any:
    # Read through the module attribute at call time (a test may patch it); old Pythons and
    # patched values give a dict of groups.
    metadata = globals().get("importlib_metadata") or __getattr__("importlib_metadata")
    found = metadata.entry_points()
    if hasattr(found, "select"):
        return found.select(group=group)
    return found.get(group, [])


class Parser:
    """Base of the markup parsers: implementations override ``load`` and
    ``get_file_extensions``; the rest is shared."""

    extensions_loaded = False
    frontend_parsers: dict[str, Any] | None = None

    @classmethod
    def load_launch_extensions(cls) -> None:
        """Import the packages that expose tags and substitutions (once per process)."""
        if Parser.extensions_loaded:
            return
        Parser.extensions_loaded = True
        for entry_point in _entry_points(EXTENSION_GROUP):
            try:
                entry_point.load()
            except Exception:
                warnings.warn(
                    f"Failed to load the launch extension: {entry_point.name}\n"
                    f"{traceback.format_exc()}",
                    stacklevel=1,
                )

    @classmethod
    def load_parser_implementations(cls) -> None:
        """Fill the table of markup implementations from the entry points (once)."""
        if Parser.frontend_parsers is not None:
            return
        parsers: dict[str, Any] = {}
        for group in PARSER_GROUPS:
            for entry_point in _entry_points(group):
                try:
                    parsers[entry_point.name] = entry_point.load()
                except Exception:
                    warnings.warn(
                        f"Failed to load the parser extension: {entry_point.name}\n"
                        f"{traceback.format_exc()}",
                        stacklevel=1,
                    )
        Parser.frontend_parsers = dict(sorted(parsers.items()))

    def parse_action(self, entity: Entity) -> Action:
        """The action of ``entity``, built by the parse method exposed for its tag."""
        self.load_launch_extensions()
        return instantiate_action(entity, self)

    def parse_substitution(self, value: str) -> list[Substitution]:
        return parse_substitution(value)

    def parse_if_substitutions(self, value: Any) -> Any:
        return parse_if_substitutions(value, self.parse_substitution)

    def escape_characters(self, value: str) -> str:
        return replace_escaped_characters(value)

    def parse_description(self, entity: Entity) -> LaunchDescription:
        """The LaunchDescription of a root ``launch`` entity."""
        from mlaunch.launch.launch_description import LaunchDescription

        if entity.type_name != "launch":
            raise RuntimeError("Expected 'launch' as root tag")
        deprecated = entity.get_attr("deprecated", optional=True)
        actions = [self.parse_action(child) for child in entity.children]
        return LaunchDescription(actions, deprecated_reason=deprecated)

    @classmethod
    def _implementations(cls) -> dict[str, Any]:
        cls.load_parser_implementations()
        assert Parser.frontend_parsers is not None
        return Parser.frontend_parsers

    @classmethod
    def get_available_extensions(cls) -> Any:
        return cls._implementations().keys()

    @classmethod
    def is_extension_valid(cls, extension: str) -> bool:
        warnings.warn(
            "Parser.is_extension_valid is deprecated, use Parser.is_filename_valid instead",
            stacklevel=1,
        )
        return extension in cls._implementations()

    @classmethod
    def get_parser_from_extension(cls, extension: str) -> Any:
        warnings.warn(
            "Parser.get_parser_from_extension is deprecated,"
            " use Parser.get_parsers_from_filename instead",
            stacklevel=1,
        )
        try:
            return cls._implementations()[extension]
        except KeyError:
            raise RuntimeError("Not recognized frontend implementation") from None

    @classmethod
    def may_parse(cls, filename: str) -> bool:
        """Whether ``filename`` ends with one of this parser's extensions."""
        return any(filename.endswith("." + ext) for ext in cls.get_file_extensions())

    @classmethod
    def is_filename_valid(cls, filename: str) -> bool:
        return any(p.may_parse(filename) for p in cls._implementations().values())

    @classmethod
    def get_parsers_from_filename(cls, filename: str) -> list[Any]:
        return [p for p in cls._implementations().values() if p.may_parse(filename)]

    @classmethod
    def get_file_extensions_from_parsers(cls) -> set[str]:
        return {ext for p in cls._implementations().values() for ext in p.get_file_extensions()}

    @classmethod
    def load(cls, file: str | os.PathLike[str] | bytes | TextIO) -> tuple[Entity, Parser]:
        """The root entity of a markup file and the parser for it: the implementations its
        name suggests first, then the others; InvalidFrontendLaunchFileError with what each
        raised when none can read it."""
        if isinstance(file, (str, bytes, os.PathLike)):
            with open(file) as fileobj:
                return cls._load_from(fileobj)
        return cls._load_from(file)

    @classmethod
    def _load_from(cls, fileobj: TextIO) -> tuple[Entity, Parser]:
        filename = str(getattr(fileobj, "name", ""))
        implementations = cls.get_parsers_from_filename(filename)
        implementations += [p for p in cls._implementations().values() if p not in implementations]
        errors: list[BaseException] = []
        for implementation in implementations:
            try:
                loaded: tuple[Entity, Parser] = implementation.load(fileobj)
                return loaded
            except Exception as e:
                errors.append(e)
                fileobj.seek(0)
        extension = os.path.splitext(filename)[1][1:] if cls.is_filename_valid(filename) else ""
        raise InvalidFrontendLaunchFileError(extension, likely_errors=errors)

    @classmethod
    def get_file_extensions(cls) -> set[str]:
        """The file extensions this parser reads (none for the base class)."""
        return set()


# importlib_metadata is served by __getattr__ (imported on first use).
__all__ = ["InvalidFrontendLaunchFileError", "Parser", "importlib_metadata"]  # noqa: F822
