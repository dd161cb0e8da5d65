"""YAML data read with bounds: every YAML file or value mlaunch reads goes through ``load``.

A parameter file is data, not code, but YAML can still make it huge or deep from a few lines:

- aliases: composing shares an anchored node among its aliases, so 30 lines of lists of aliases
  of lists (a "billion laughs") compose at once and only explode when walked (``--print``,
  converting, flattening ROS 1 parameters: until memory runs out). ``check_aliases`` counts each
  node's expanded size once, iteratively, and stops when aliases add more than
  ``ALIAS_LIMIT`` nodes to what the text itself holds; a file without aliases is never limited
  (a 1,000,000-key parameter file stays readable).
- depth: libyaml composes recursively in C (a segmentation fault past ~20,000 levels), PyYAML's
  Python composer and every later walk recursively (RecursionError; ROS 1 parameters 3,000
  deep ended so). Past ``DEPTH_LIMIT`` levels the text is refused, found by a flat pass over
  its events.

Both are a ``YamlLimitError`` (a ``LaunchFileError``) at the line and column of the node.
"""

from __future__ import annotations

import sys

from mlaunch.plan.errors import LaunchFileError

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

    from yaml.nodes import Node

# Nodes aliases may add to a document beyond those written in it.
ALIAS_LIMIT = 200_000
# Nested maps and lists a parameter document may have: real ones nest a dozen; every later
# walk of the data (flattening, JSON, XML-RPC to a ROS 1 master) is recursive too.
DEPTH_LIMIT = 200
# Frames the walks of such data may take (PyYAML's Python composer ~3 per level), on top of a
# launch tree's own (mlaunch.frontends.limits gives those 25,000): pure Python frames do not use
# the C stack in Python 3.11+.
_RECURSION_LIMIT = 25_000


class YamlLimitError(LaunchFileError):
    """YAML text past one of the bounds (aliases, depth), located at the node."""


def load(text: str | bytes, where: str = "", *, loader: Any = None) -> Any:
    """The data of one YAML document, as ``yaml.safe_load`` (or ``loader``) gives it, bounded.

    ``where`` names the text in errors (a file, ``file:line`` of the attribute holding it); a
    bound passed is a ``YamlLimitError`` at ``where:line:col``. Syntax errors are PyYAML's own,
    as ``yaml.safe_load`` raises them, for the caller to word.
    """
    import yaml

    if loader is None:
        loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    bound = bound_of_depth(text)
    if bound > DEPTH_LIMIT:
        check_depth(
            text,
            loader,
            DEPTH_LIMIT,
            lambda mark: YamlLimitError(
                f"YAML maps and lists nest deeper than {DEPTH_LIMIT} levels, mlaunch's limit"
                " (generated nesting?)",
                where=_place(where, mark),
            ),
        )
    if bound > 50 and sys.getrecursionlimit() < _RECURSION_LIMIT:
        sys.setrecursionlimit(_RECURSION_LIMIT)
    reader = loader(text)
    try:
        root = reader.get_single_node()
        if root is None:
            return None
        # An alias needs an anchor ('&'), and '*' alone is common ('/**:' in every params file).
        if isinstance(text, bytes):
            aliased = b"&" in text and b"*" in text
        else:
            aliased = "&" in text and "*" in text
        if aliased:
            check_aliases(root, lambda node, message: _error(where, node, message))
        return reader.construct_document(root)
    finally:
        reader.dispose()


def check_depth(
    text: str | bytes,
    loader: Any,
    limit: int,
    error: Callable[[Any], Exception],
) -> None:
    """Raise ``error(mark)`` where ``text`` nests deeper than ``limit`` maps and lists.

    A flat walk over the parser's events: composing is recursive (libyaml's in C crashes the
    interpreter ~20,000 levels deep, a segmentation fault, not an exception).
    """
    import yaml
    from yaml.events import CollectionEndEvent, CollectionStartEvent

    depth = 0
    for event in yaml.parse(text, Loader=loader):
        if isinstance(event, CollectionStartEvent):
            depth += 1
            if depth > limit:
                raise error(event.start_mark)
        elif isinstance(event, CollectionEndEvent):
            depth -= 1


def check_aliases(
    root: Node,
    error: Callable[[Node, str], Exception],
    limit: int = ALIAS_LIMIT,
) -> None:
    """Raise ``error(node, message)`` where aliases expand a node past ``limit`` nodes more than
    the document holds, or into itself (an alias inside the list or map it names).

    Each node's expanded size is counted once, children first: without aliases a node's size
    never exceeds the nodes counted so far, so only what aliases add is limited.
    """
    from yaml.nodes import MappingNode, SequenceNode

    def children(node: Node) -> list[Node]:
        if isinstance(node, SequenceNode):
            return list(node.value)
        if isinstance(node, MappingNode):
            return [n for pair in node.value for n in pair]
        return []

    sizes: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[Node, bool]] = [(root, False)]
    while stack:
        node, finished = stack.pop()
        key = id(node)
        if finished:
            on_path.discard(key)
            size = 1 + sum(sizes[id(c)] for c in children(node))
            if size > len(sizes) + 1 + limit:
                raise error(
                    node,
                    f"YAML aliases expand this {shape(node)[2:]} by more than {limit:,} nodes,"
                    " mlaunch's limit (an alias bomb?)",
                )
            sizes[key] = size
        elif key in on_path:
            raise error(node, f"a YAML alias repeats the {shape(node)[2:]} it is in")
        elif key not in sizes:
            on_path.add(key)
            stack.append((node, True))
            stack.extend((c, False) for c in children(node))


def shape(node: Node) -> str:
    """``a list``, ``a map``, or a scalar's text, for messages."""
    from yaml.nodes import MappingNode, SequenceNode

    if isinstance(node, SequenceNode):
        return "a list"
    if isinstance(node, MappingNode):
        return "a map"
    return repr(node.value)


def bound_of_depth(text: str | bytes) -> int:
    """An upper bound of the nesting depth, without parsing.

    A block map nested in another is indented deeper; a block list entry is ``-`` and white
    space (at the same indentation as its map's key too); a flow collection opens with ``[`` or
    ``{``; a complex key with ``?``. So a URDF's ``:`` and ``-1.57`` count for nothing (counting
    every ``:`` and ``-`` made a 48 MB URDF take a parse pass of its own).
    """
    import re

    if isinstance(text, bytes):
        indents = re.findall(rb"(?m)^ +", text)
        marks = sum(text.count(m) for m in (b"- ", b"-\n", b"-\r", b"-\t", b"[", b"{", b"?"))
    else:
        indents = re.findall(r"(?m)^ +", text)
        marks = sum(text.count(m) for m in ("- ", "-\n", "-\r", "-\t", "[", "{", "?"))
    return max(map(len, indents), default=0) + marks + 2  # a '-' that ends the text


def _place(where: str, mark: Any) -> str:
    line = f"{mark.line + 1}:{mark.column + 1}"
    return f"{where}:{line}" if where else line


def _error(where: str, node: Node, message: str) -> YamlLimitError:
    return YamlLimitError(message, where=_place(where, node.start_mark))
