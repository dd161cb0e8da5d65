"""One tag of a YAML or XML launch file, read strictly: every attribute and child must be used.

The XML and YAML readers each turn their parse tree into Element objects (what upstream calls
an entity; ``launch.frontend.Entity`` is upstream's API over one: ``frontends/markup.py``). The
tag builders (``mlaunch.frontends.tags``) read them through the typed getters below, which parse
``$(...)`` once and check literal values at load time. ``finish()`` then rejects whatever was
not read, naming the file, line, tag and the attributes that would have been valid (ROS 2's
``assert_entity_completely_parsed``, with positions).

Value typing follows ROS 2: XML attributes are strings coerced to the type the attribute is
declared with; YAML scalars keep their type and are checked (a number where text is wanted is
written as text, a map or list where text is wanted is an error).
"""

from __future__ import annotations

import difflib
from collections.abc import Callable

from mlaunch.launch.frontend.template import Parts, TemplateError
from mlaunch.launch.substitutions.boolean_substitution import to_bool
from mlaunch.launch_ros.subst import parse_template
from mlaunch.plan.errors import LaunchFileError, SubstitutionFailure

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms to import
if TYPE_CHECKING:
    from typing import Any

# The literal values conditions accept (ROS 2's evaluate_condition_expression).
CONDITION_WORDS = ("true", "false", "1", "0")

_YAML_STR = "tag:yaml.org,2002:str"
_YAML_BOOL = "tag:yaml.org,2002:bool"
_YAML_INT = "tag:yaml.org,2002:int"
_YAML_FLOAT = "tag:yaml.org,2002:float"
_YAML_NULL = "tag:yaml.org,2002:null"


class MissingAttributeError(LaunchFileError, AttributeError):
    """A required attribute is not there (an AttributeError, as upstream's Element raises)."""


class UnexpectedEntityError(LaunchFileError, ValueError):
    """An attribute or nested tag nothing read (a ValueError, as upstream raises it)."""


class Attr:
    """An attribute value and where its text starts (1-based line and column).

    ``value`` is the XML string, or the YAML node (``yaml.Node``) for YAML files. ``locate``,
    when given, computes the position on demand (XML: only an error needs it).
    A plain class: dataclasses costs ~8 ms to import on every YAML/XML launch.
    """

    __slots__ = ("col", "line", "locate", "value")

    def __init__(
        self,
        value: Any,
        line: int,
        col: int,
        locate: Callable[[], tuple[int, int]] | None = None,
    ) -> None:
        self.value = value
        self.line = line
        self.col = col
        self.locate = locate

    def __repr__(self) -> str:
        return f"Attr({self.value!r}, line={self.line}, col={self.col})"

    def position(self) -> tuple[int, int]:
        if self.locate is not None:
            self.line, self.col = self.locate()
            self.locate = None
        return self.line, self.col


class Element:
    """A tag with its attributes and child entities, in either format."""

    __slots__ = (
        "_actions_read",
        "_asked",
        "_sub_tags",
        "_used",
        "attrs",
        "children",
        "col",
        "fmt",
        "line",
        "path",
        "tag",
        "yaml_construct",
        "yaml_subentities",
    )

    def __init__(
        self,
        tag: str,
        path: str,
        line: int,
        col: int,
        fmt: str,  # "xml" or "yaml"
        attrs: dict[str, Attr] | None = None,
        # XML: the child elements. YAML: the children list (a list value, or `children`).
        children: list[Element] | None = None,
        # YAML only: builds Entities for a list-of-maps attribute (param, remap, env ...).
        yaml_subentities: Any = None,
        # YAML only: turns a node into Python data.
        yaml_construct: Any = None,
    ) -> None:
        self.tag = tag
        self.path = path
        self.line = line
        self.col = col
        self.fmt = fmt
        self.attrs: dict[str, Attr] = {} if attrs is None else attrs
        self.children = children
        self.yaml_subentities = yaml_subentities
        self.yaml_construct = yaml_construct
        self._asked: dict[str, None] = {}
        self._used: set[str] = set()
        self._sub_tags: dict[str, None] = {}
        self._actions_read = False

    def __repr__(self) -> str:
        return f"Element({self.tag!r}, {self.path}:{self.line}:{self.col})"

    # --- where and what -------------------------------------------------------------------------

    @property
    def what(self) -> str:
        return f"<{self.tag}>" if self.fmt == "xml" else self.tag

    @property
    def origin(self) -> str:
        """``file:line`` of the tag, what actions carry as their origin."""
        return f"{self.path}:{self.line}"

    def where(self, attr: Attr | None = None, index: int = 0) -> str:
        if attr is None:
            return f"{self.path}:{self.line}:{self.col}"
        line, col = attr.position()
        text = attr.value if isinstance(attr.value, str) else getattr(attr.value, "value", "")
        if isinstance(text, str) and index:
            prefix = text[:index]
            newlines = prefix.count("\n")
            if newlines:
                line += newlines
                col = index - prefix.rfind("\n")
            else:
                col += index
        return f"{self.path}:{line}:{col}"

    def error(
        self,
        message: str,
        attr: Attr | None = None,
        index: int = 0,
        kind: type[LaunchFileError] = LaunchFileError,
    ) -> LaunchFileError:
        return kind(message, where=self.where(attr, index), what=self.what)

    # --- reading attributes ---------------------------------------------------------------------

    def _take(self, name: str, required: bool) -> Attr | None:
        self._asked.setdefault(name, None)
        attr = self.attrs.get(name)
        if attr is None:
            if required:
                raise self.error(self._missing(name), kind=MissingAttributeError)
            return None
        self._used.add(name)
        return attr

    def _missing(self, name: str) -> str:
        unknown = [a for a in self.attrs if a not in self._asked]
        close = difflib.get_close_matches(name, unknown, n=1, cutoff=0.6)
        hint = f" (found {close[0]!r}: a typo?)" if close else ""
        return f"missing required attribute {name!r}{hint}"

    def has(self, name: str) -> bool:
        """Whether the attribute is present (counts as asked, not as read)."""
        self._asked.setdefault(name, None)
        return name in self.attrs

    def attr(self, name: str, *, required: bool = False) -> Attr | None:
        """The raw attribute (for values with their own typing rules: param, set_parameter)."""
        return self._take(name, required)

    def text(self, name: str, *, required: bool = False) -> str | Parts | None:
        """A substitutable text attribute: a plain str, or a list of str and substitutions."""
        attr = self._take(name, required)
        if attr is None:
            return None
        return self.template(attr, self.scalar_text(attr, name))

    def literal(self, name: str, *, required: bool = False) -> str | None:
        """A text attribute that must be written out, without substitutions (arg names)."""
        attr = self._take(name, required)
        if attr is None:
            return None
        if self.yaml_native(attr, (_YAML_BOOL,)) is not None:
            raise self.error(
                f"attribute {name!r} is {attr.value.value!r}, which YAML reads as a boolean;"
                " quote it to mean the text",
                attr,
            )
        text = self.scalar_text(attr, name)
        if "$(" in text:
            raise self.error(
                f"attribute {name!r} must be plain text, without substitutions: {text!r}", attr
            )
        return text

    def flag(self, name: str, *, dynamic: bool = True) -> bool | Parts | None:
        """A boolean attribute: a bool, or substitutions performed to one when resolving."""
        attr = self._take(name, False)
        if attr is None:
            return None
        native = self.yaml_native(attr, (_YAML_BOOL,))
        if native is not None:
            return bool(native)
        text = self.scalar_text(attr, name, expect="a boolean")
        value = self._dynamic(attr, text, name, dynamic)
        if value is not None:
            return value
        try:
            return to_bool(text, name)
        except SubstitutionFailure:
            raise self.error(
                f"attribute {name!r} is {text!r}, expected a boolean (true, false, 1, 0)", attr
            )

    def number(
        self, name: str, kind: type[float] | type[int] = float, *, minimum: float | None = None
    ) -> float | int | Parts | None:
        """A number attribute (``kind`` int or float), or substitutions."""
        attr = self._take(name, False)
        if attr is None:
            return None
        tags = (_YAML_INT,) if kind is int else (_YAML_INT, _YAML_FLOAT)
        native = self.yaml_native(attr, tags)
        word = "an integer" if kind is int else "a number"
        if native is not None:
            value = kind(native)
        else:
            text = self.scalar_text(attr, name, expect=word)
            dynamic = self._dynamic(attr, text, name, True)
            if dynamic is not None:
                return dynamic
            try:
                value = kind(text.strip())
            except ValueError:
                raise self.error(f"attribute {name!r} is {text!r}, expected {word}", attr)
        if minimum is not None and value < minimum:
            raise self.error(f"attribute {name!r} is {value!r}, must be >= {minimum:g}", attr)
        return value

    def condition_text(self, name: str) -> str | Parts | None:
        """An if/unless expression; a literal one must be true, false, 1 or 0."""
        value = self.text(name)
        if isinstance(value, str) and value.strip().lower() not in CONDITION_WORDS:
            raise self.error(
                f"{name}={value!r} is not a condition value; valid: true, false, 1, 0"
                " (or a substitution that performs to one)",
                self.attrs[name],
            )
        return value

    # --- children -------------------------------------------------------------------------------

    def subentities(self, name: str) -> list[Element]:
        """The ``name`` sub-entities (XML child tags; YAML a list of maps under key ``name``)."""
        self._sub_tags.setdefault(name, None)
        if self.fmt == "xml":
            return [c for c in self.children or () if c.tag == name]
        attr = self._take(name, False)
        if attr is None:
            return []
        return self.yaml_subentities(self, name, attr)  # type: ignore[no-any-return]

    def actions(self) -> list[Element]:
        """The child action entities (group, timer, launch)."""
        self._actions_read = True
        if self.fmt == "xml":
            return [c for c in self.children or () if c.tag not in self._sub_tags]
        return list(self.children or ())

    def nested(self) -> list[Element]:
        """Every child entity, all of them counted as read (upstream's ``Element.children``)."""
        self._actions_read = True
        return list(self.children or ())

    def finish(self) -> None:
        """Reject any attribute or child that no getter read."""
        for name, attr in self.attrs.items():
            if name not in self._used:
                raise self.error(self._unknown_attribute(name), attr, kind=UnexpectedEntityError)
        if self.children is not None and not self._actions_read:
            if self.fmt == "yaml":
                raise self.error(f"{self.tag} takes no child entities", kind=UnexpectedEntityError)
            for child in self.children:
                if child.tag not in self._sub_tags:
                    valid = ", ".join(f"<{t}>" for t in self._sub_tags) or "none"
                    hint = _did_you_mean(child.tag, self._sub_tags)
                    raise UnexpectedEntityError(
                        f"unexpected tag {child.what}{hint}; valid children: {valid}",
                        where=child.where(),
                        what=self.what,
                    )

    def _unknown_attribute(self, name: str) -> str:
        known = [a for a in self._asked if a not in ("if", "unless")]
        if self.fmt == "yaml":
            known += [t for t in self._sub_tags if t not in known]
        hint = _did_you_mean(name, [*known, "if", "unless"])
        if name == "children" and self.fmt == "yaml":
            return f"{self.tag} takes no children"
        valid = ", ".join(known) or "none"
        return f"unknown attribute {name!r}{hint}; valid attributes: {valid}"

    # --- values ---------------------------------------------------------------------------------

    def scalar_text(self, attr: Attr, name: str, expect: str = "text") -> str:
        """The attribute as text: XML as written, YAML scalars written out (bools lowercase)."""
        value = attr.value
        if isinstance(value, str):
            return value
        kind = type(value).__name__
        if kind == "ScalarNode":
            tag = value.tag
            if tag == _YAML_STR:
                return str(value.value)
            if tag == _YAML_BOOL:
                return "true" if self.yaml_construct(value) else "false"
            if tag in (_YAML_INT, _YAML_FLOAT):
                return str(value.value)
            if tag == _YAML_NULL:
                raise self.error(
                    f'attribute {name!r} is empty (null); write {expect} ("" for empty text)',
                    attr,
                )
            return str(value.value)
        shape = "a list" if kind == "SequenceNode" else "a map"
        raise self.error(f"attribute {name!r} is {shape}, expected {expect}", attr)

    def template(self, attr: Attr, text: str) -> str | Parts:
        try:
            parts = parse_template(text)
        except TemplateError as e:
            if e.unknown is None or not load_extensions():
                raise self.error(f"{e.message} in {_excerpt(text, e.index)}", attr, e.index)
            return self.template(attr, text)  # a package's extension may expose the name
        if len(parts) == 1 and isinstance(parts[0], str):
            return parts[0]
        return parts

    def _dynamic(self, attr: Attr, text: str, name: str, allowed: bool) -> Parts | None:
        """Substitutions in a typed attribute, to be performed when resolving."""
        if "$(" not in text:
            return None
        if not allowed:
            raise self.error(
                f"attribute {name!r} cannot hold substitutions (it is needed before resolving):"
                f" {text!r}",
                attr,
            )
        value = self.template(attr, text)
        return value if isinstance(value, list) else None

    def yaml_native(self, attr: Attr, tags: tuple[str, ...]) -> Any:
        node = attr.value
        if isinstance(node, str) or type(node).__name__ != "ScalarNode" or node.tag not in tags:
            return None
        return self.yaml_construct(node)


def load_extensions() -> bool:
    """Import the packages that expose tags and substitutions (entry points
    ``launch.frontend.launch_extension``), once; whether this call loaded them.

    Only a tag or substitution name outside the built-in tables pays for it. They import
    ``launch.*``: the application serves those names from mlaunch before it loads a launch file
    (``mlaunch.compat``), as for a Python launch file.
    """
    from mlaunch.launch.frontend.parser import Parser

    if Parser.extensions_loaded:
        return False
    Parser.load_launch_extensions()
    return True


def _did_you_mean(name: str, options: Any) -> str:
    close = difflib.get_close_matches(name, list(options), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def did_you_mean(name: str, options: Any) -> str:
    """`` (did you mean 'x'?)`` when a close option exists, else empty."""
    return _did_you_mean(name, options)


def _excerpt(text: str, index: int, width: int = 60) -> str:
    """``text`` quoted, cut to ``width`` characters either side of ``index`` when it is long
    (one error line, not a 60 KB generated attribute)."""
    if len(text) <= 3 * width:
        return repr(text)
    start, end = max(0, index - width), index + width
    return ("..." if start else "") + repr(text[start:end]) + ("..." if end < len(text) else "")
