"""The bridge between mlaunch's readers and upstream's ``launch.frontend`` API.

``MarkupEntity`` is an upstream Entity (``type_name``, ``children``, ``get_attr``,
``assert_entity_completely_parsed``) over one of the readers' located entities, so a parse
method a package exposed reads a tag the way it does under ros2 launch, and what it leaves
unread is reported with file:line. ``MarkupParser`` is the base of ``launch_xml.Parser`` and
``launch_yaml.Parser``: the built-in tags are built by the readers' own table
(``mlaunch.frontends.tags``), any other tag by the parse method exposed for it
(``build_exposed``, which the readers call too).
"""

from __future__ import annotations

import importlib
import os

from mlaunch.frontends.element import (
    Element as ReaderEntity,
)
from mlaunch.frontends.element import (
    MissingAttributeError,
    UnexpectedEntityError,
    load_extensions,
)
from mlaunch.launch.frontend.coercion import get_typed_value, is_instance_of
from mlaunch.launch.frontend.entity import Entity as FrontendEntity
from mlaunch.launch.frontend.parser import Parser
from mlaunch.launch.frontend.type_utils import check_is_list_entity
from mlaunch.launch.substitution import TextSubstitution
from mlaunch.plan.errors import LaunchFileError, MlaunchError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any, TextIO

    from mlaunch.launch.action import Action
    from mlaunch.launch.launch_description import LaunchDescription
    from mlaunch.launch.substitution import Substitution

# The exceptions a parse method written against upstream raises for bad input.
PARSE_ERRORS = (AttributeError, LookupError, RuntimeError, TypeError, ValueError)


class AttributeTypeError(LaunchFileError, TypeError):
    """An attribute that is not of the type its reader asked for (a TypeError, as upstream)."""


class MarkupEntity(FrontendEntity):
    """An upstream Entity over a reader entity; XML coerces text, YAML checks values."""

    def __init__(self, inner: ReaderEntity, *, parent: MarkupEntity | None = None) -> None:
        self.inner = inner
        self._parent = parent

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.inner!r})"

    @property
    def type_name(self) -> str:
        return self.inner.tag

    @property
    def parent(self) -> MarkupEntity | None:
        return self._parent

    @property
    def children(self) -> list[FrontendEntity]:
        inner = self.inner
        if inner.children is None and inner.fmt == "yaml":
            raise inner.error(
                f"expected entity `{inner.tag}` to have children entities (a list of entities,"
                " or a map with a 'children' list)",
                kind=UnexpectedEntityError,
            )
        return [self.wrap(child) for child in inner.nested()]

    def wrap(self, child: ReaderEntity) -> MarkupEntity:
        return type(self)(child, parent=self)

    def get_attr(
        self,
        name: str,
        *,
        data_type: Any = str,
        optional: bool = False,
        can_be_str: bool = True,
    ) -> Any:
        inner = self.inner
        if check_is_list_entity(data_type):
            found = inner.subentities(name)
            if not found:
                if optional:
                    return None
                raise inner.error(f"missing sub-entities {name!r}", kind=MissingAttributeError)
            return [self.wrap(sub) for sub in found]
        attr = inner.attr(name, required=not optional)
        if attr is None:
            return None
        if inner.fmt == "yaml":
            value = inner.yaml_construct(attr.value)
            if not is_instance_of(value, data_type, can_be_str=can_be_str):
                raise inner.error(
                    f"attribute {name!r} is {value!r}, expected {_type_name(data_type)}",
                    attr,
                    kind=AttributeTypeError,
                )
            return value
        text: str | list[str] = attr.value
        separator = inner.attr(f"{name}-sep")
        if separator is not None:
            text = attr.value.split(separator.value)
        try:
            return get_typed_value(text, data_type, can_be_str=can_be_str)
        except ValueError:
            raise inner.error(
                f"attribute {name!r} is {attr.value!r}, which is not {_type_name(data_type)}",
                attr,
                kind=AttributeTypeError,
            ) from None

    def assert_entity_completely_parsed(self) -> None:
        self.inner.finish()


def _type_name(data_type: Any) -> str:
    if data_type is None:
        return "a value YAML can read"
    return getattr(data_type, "__name__", None) or str(data_type)


class MarkupParser(Parser):
    """A parser of mlaunch's readers: built-in tags from the readers' table, others exposed."""

    entity_class: type[MarkupEntity] = MarkupEntity
    # The format's reader: the root entity of a file's bytes, its errors located in the name.
    reader: Callable[[bytes, str], ReaderEntity]
    extensions: frozenset[str] = frozenset()

    @classmethod
    def read(cls, data: bytes, name: str) -> ReaderEntity:
        return cls.reader(data, name)

    @classmethod
    def get_file_extensions(cls) -> set[str]:
        return set(cls.extensions)

    @classmethod
    def load(cls, file: Any) -> tuple[FrontendEntity, Parser]:
        data, name = read_source(file)
        return cls.entity_class(cls.read(data, name)), cls()

    def parse_substitution(self, value: str) -> list[Substitution]:
        """The substitutions of ``value``, launch_ros's names included (as the readers)."""
        from mlaunch.launch_ros.subst import parse_template

        return [
            TextSubstitution(text=p) if isinstance(p, str) else p for p in parse_template(value)
        ]

    def parse_action(self, entity: FrontendEntity) -> Action:
        if not isinstance(entity, MarkupEntity):
            return super().parse_action(entity)
        from mlaunch.frontends.tags import build_action

        try:
            action: Action = build_action(entity.inner, self)
        except MlaunchError as e:
            raise upstream_labelled(e) from None
        return action

    def parse_description(self, entity: FrontendEntity) -> LaunchDescription:
        if not isinstance(entity, MarkupEntity):
            return super().parse_description(entity)
        from mlaunch.frontends.tags import build_description

        try:
            return build_description(entity.inner, self)
        except MlaunchError as e:
            raise upstream_labelled(e) from None


def upstream_labelled(error: MlaunchError) -> MlaunchError:
    """The error with its tag named as upstream's messages name it (`` `arg` ``, not ``<arg>``)."""
    what = error.what
    if what and not what.startswith("`"):
        error.what = f"`{what.strip('<>')}`"
    return error


def read_source(file: str | os.PathLike[str] | bytes | TextIO) -> tuple[bytes, str]:
    """The bytes of a path or an open file, and the name its errors are located in."""
    if isinstance(file, (str, bytes, os.PathLike)):
        name = os.fsdecode(file)
        try:
            with open(file, "rb") as f:
                return f.read(), name
        except OSError as e:
            raise LaunchFileError(f"cannot read launch file: {e.strerror}", where=name) from None
    content = file.read()
    data = content.encode() if isinstance(content, str) else bytes(content)
    label = getattr(file, "name", None)
    return data, label if isinstance(label, str) else "<stream>"


# The parser module of each reader format (launch_xml, launch_yaml).
_FORMATS = {"xml": "mlaunch.frontends.launch_xml", "yaml": "mlaunch.frontends.launch_yaml"}


def build_exposed(e: ReaderEntity, parser: Parser | None, unknown: Callable[[str], str]) -> Action:
    """The action a package exposed for the tag of ``e`` (``expose_action``), located at it;
    ``unknown(tag)`` says what is wrong when no package did."""
    from mlaunch.launch.frontend.expose import action_parse_methods, instantiate_action

    load_extensions()
    if e.tag not in action_parse_methods:
        raise e.error(unknown(e.tag))
    module = importlib.import_module(_FORMATS[e.fmt])
    if not isinstance(parser, MarkupParser):
        parser = module.Parser()
    try:
        action = instantiate_action(module.Entity(e), parser)
    except MlaunchError as err:
        if not (err.where or "").startswith(e.path):
            err.where, err.what = e.where(), e.what
        raise
    except PARSE_ERRORS as err:
        raise e.error(f"{type(err).__name__}: {err}") from err
    action.origin = e.origin
    return action
