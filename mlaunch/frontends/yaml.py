"""The YAML frontend: a ``*.launch.yaml`` file (ROS 2's launch_yaml schema) to a LaunchDescription.

The file is composed (not constructed) with PyYAML's C loader when it is there, so every tag and
value keeps its line and column; scalars are constructed one by one as the tag builders read
them. The root is ``launch:`` with a list of single-key maps (tag: attributes); an entity that
holds actions is a list, or a map with a ``children:`` list.
"""

from __future__ import annotations

import yaml
from yaml.constructor import SafeConstructor
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from mlaunch.frontends.element import Attr, Element
from mlaunch.frontends.limits import DEPTH_LIMIT, too_deep
from mlaunch.frontends.tags import build_description
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.yamldata import bound_of_depth, check_aliases, check_depth, shape

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_description import LaunchDescription

try:
    _Base: Any = yaml.CSafeLoader
except AttributeError:  # PyYAML built without libyaml
    _Base = yaml.SafeLoader


class _Loader(_Base):  # type: ignore[misc]
    """The safe loader (C when available); composing with it keeps node marks."""


def load(path: str) -> LaunchDescription:
    """The LaunchDescription of the YAML launch file at ``path``."""
    return build_description(read_root(path))


def read_root(path: str) -> Element:
    """The root ``launch`` Element of the YAML file at ``path`` (read, not built)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise LaunchFileError(f"cannot read launch file: {e.strerror}", where=path)
    return parse_root(data, path)


def parse_root(data: bytes, path: str) -> Element:
    """The root ``launch`` Element of YAML text, its errors located in ``path``."""
    return _Reader(path).root(data)


class _Reader:
    """Turns composed YAML nodes into Entities, located in ``path``."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.constructor = SafeConstructor()

    def root(self, data: bytes) -> Element:
        try:
            if bound_of_depth(data) > _NODE_DEPTH_LIMIT:
                self.check_depth(data)
            root = yaml.compose(data, Loader=_Loader)
        except yaml.MarkedYAMLError as e:
            raise self._yaml_error(e)
        except yaml.reader.ReaderError as e:  # a byte or character that is not YAML text
            from mlaunch.frontends.encoding import not_utf8  # error path only

            raise not_utf8(data, self.path) or self._reader_error(data, e)
        except yaml.YAMLError as e:
            raise LaunchFileError(f"malformed YAML: {e}", where=self.path)
        if root is None:
            raise LaunchFileError("the file is empty; expected a 'launch:' list", where=self.path)
        if b"&" in data:  # an anchor: aliases may repeat what it names (no '&', no alias)
            self.check_expansion(root)
        if not isinstance(root, MappingNode) or len(root.value) != 1:
            raise self.error(root, "the root must be a map with the single key 'launch'")
        key, value = root.value[0]
        tag = self.key_text(key)
        if tag != "launch":
            raise self.error(key, f"the root key must be 'launch', not {tag!r}")
        return self.entity(tag, key, value)

    def check_depth(self, data: bytes) -> None:
        """Stop a file nested deeper than the limit before composing it (libyaml composes
        recursively in C: ~20,000 levels crash the interpreter)."""
        check_depth(
            data,
            _Loader,
            _NODE_DEPTH_LIMIT,
            lambda mark: too_deep(self.where(mark), "YAML maps and lists", _NODE_DEPTH_LIMIT),
        )

    def check_expansion(self, root: Node) -> None:
        """Stop aliases that expand the file past ``ALIAS_LIMIT`` more nodes, or into itself.

        Composing shares an anchored node among its aliases, so a 75-line file of lists of
        aliases of lists (a "billion laughs") composes at once and only explodes when walked:
        24 levels took 6.5 GB, 16 planned 131,071 processes. ``check_aliases`` counts each
        node's expanded size once, before any entity is built (parameter files get the same).
        """
        check_aliases(root, self.error)

    # --- nodes to entities ----------------------------------------------------------------------

    def entity(self, tag: str, key: Node, value: Node) -> Element:
        mark = key.start_mark
        e = Element(
            tag=tag,
            path=self.path,
            line=mark.line + 1,
            col=mark.column + 1,
            fmt="yaml",
            yaml_subentities=self.subentities,
            yaml_construct=self.construct,
        )
        if isinstance(value, SequenceNode):
            e.children = self.children(value)
        elif isinstance(value, MappingNode):
            self.fill(e, value)
        elif not (isinstance(value, ScalarNode) and value.tag == "tag:yaml.org,2002:null"):
            raise self.error(
                value,
                f"{tag}: expected a map of attributes or a list of children, got {value.value!r}",
            )
        return e

    def fill(self, e: Element, mapping: MappingNode) -> None:
        for key, value in mapping.value:
            name = self.key_text(key)
            if name in e.attrs or (name == "children" and e.children is not None):
                raise self.error(key, f"{e.tag}: key {name!r} is given twice")
            if name == "children":
                if not isinstance(value, SequenceNode):
                    raise self.error(value, f"{e.tag}: 'children' must be a list of entities")
                e.children = self.children(value)
                continue
            e.attrs[name] = self.attr(value)

    def children(self, sequence: SequenceNode) -> list[Element]:
        out = []
        for item in sequence.value:
            if not isinstance(item, MappingNode) or len(item.value) != 1:
                keys = (
                    ", ".join(repr(self.key_text(k)) for k, _ in item.value)
                    if isinstance(item, MappingNode)
                    else ""
                )
                got = f"a map with keys {keys}" if keys else f"{shape(item)}"
                raise self.error(
                    item,
                    f"each entity is a map with one key, its tag (- node: {{...}}); got {got}"
                    " (check the indentation and the '-' of each entity)",
                )
            key, value = item.value[0]
            out.append(self.entity(self.key_text(key), key, value))
        return out

    def subentities(self, parent: Element, name: str, attr: Attr) -> list[Element]:
        """A list-of-maps attribute (``param``, ``remap``, ``env`` ...) as Entities."""
        node = attr.value
        if not isinstance(node, SequenceNode) or not all(
            isinstance(i, MappingNode) for i in node.value
        ):
            raise parent.error(f"attribute {name!r} must be a list of maps (- {{...}} items)", attr)
        out = []
        for item in node.value:
            mark = item.start_mark
            e = Element(
                tag=name,
                path=self.path,
                line=mark.line + 1,
                col=mark.column + 1,
                fmt="yaml",
                yaml_subentities=self.subentities,
                yaml_construct=self.construct,
            )
            self.fill(e, item)
            out.append(e)
        return out

    def attr(self, node: Node) -> Attr:
        mark = node.start_mark
        quoted = 1 if isinstance(node, ScalarNode) and node.style in ("'", '"') else 0
        return Attr(node, mark.line + 1, mark.column + 1 + quoted)

    def key_text(self, key: Node) -> str:
        if not isinstance(key, ScalarNode) or key.tag != "tag:yaml.org,2002:str":
            raise self.error(key, f"expected a tag or attribute name, got {shape(key)}")
        return str(key.value)

    def construct(self, node: Node) -> Any:
        return self.constructor.construct_object(node, deep=True)

    # --- errors ---------------------------------------------------------------------------------

    def error(self, node: Node, message: str) -> LaunchFileError:
        return LaunchFileError(message, where=self.where(node.start_mark))

    def where(self, mark: Any) -> str:
        """``path:line:col`` of a mark (PyYAML's or libyaml's; None: the file)."""
        if mark is None:
            return self.path
        return f"{self.path}:{mark.line + 1}:{mark.column + 1}"

    def _reader_error(self, data: bytes, e: yaml.reader.ReaderError) -> LaunchFileError:
        text = data.decode("utf-8", "replace")[: e.position]
        line, col = text.count("\n") + 1, e.position - (text.rfind("\n") + 1) + 1
        what = f"#x{e.character:04x}" if isinstance(e.character, int) else repr(e.character)
        return LaunchFileError(
            f"the character {what} is not allowed in YAML ({e.reason})",
            where=f"{self.path}:{line}:{col}",
        )

    def _yaml_error(self, e: yaml.MarkedYAMLError) -> LaunchFileError:
        mark = e.problem_mark or e.context_mark
        where = f"{self.path}:{mark.line + 1}:{mark.column + 1}" if mark else self.path
        problem = " ".join(p for p in (e.context, e.problem) if p)
        return LaunchFileError(f"malformed YAML: {problem}", where=where)


# A nesting level of groups is two or three YAML levels (a map, its children list ...).
_NODE_DEPTH_LIMIT = 3 * DEPTH_LIMIT
