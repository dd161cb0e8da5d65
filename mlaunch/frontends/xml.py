"""The XML frontend: a ``*.launch.xml`` file (ROS 2's launch_xml schema) to a LaunchDescription.

Parsed with expat directly, so every element knows its line and column and every attribute
where its value starts (for ``$(...)`` errors pointing at the column). Attributes are strings,
coerced by the type each tag declares for them (``mlaunch.frontends.element``).
"""

from __future__ import annotations

import re
from functools import partial
from xml.parsers import expat

from mlaunch.frontends.element import Attr, Element
from mlaunch.frontends.limits import DEPTH_LIMIT, too_deep
from mlaunch.frontends.tags import build_description
from mlaunch.plan.errors import LaunchFileError

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_description import LaunchDescription

# Attributes the root may carry for XML tooling (schema hints), not for launch.
_ROOT_IGNORED = re.compile(r"^(xmlns(:.*)?|xsi:.*)$")
_ATTRIBUTE = re.compile(rb"\s*([^\s=/>]+)\s*=\s*([\"'])")


def load(path: str) -> LaunchDescription:
    """The LaunchDescription of the XML launch file at ``path``."""
    return build_description(read_root(path))


def read_root(path: str) -> Element:
    """The root Element of the XML file at ``path`` (read, not built)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise LaunchFileError(f"cannot read launch file: {e.strerror}", where=path)
    return parse_root(data, path)


def parse_root(data: bytes, path: str) -> Element:
    """The root Element of XML text, its errors located in ``path``."""
    root = _TreeBuilder(path, data).parse()
    for name in [n for n in root.attrs if _ROOT_IGNORED.match(n)]:
        del root.attrs[name]
    return root


class _TreeBuilder:
    """expat callbacks building Entities with positions."""

    def __init__(self, path: str, data: bytes) -> None:
        self.path = path
        self.data = data
        self.parser = expat.ParserCreate()
        # Unbuffered text: the handler runs where the text is, so its position is right.
        self.parser.buffer_text = False
        self.parser.StartElementHandler = self.start
        self.parser.EndElementHandler = self.end
        self.parser.CharacterDataHandler = self.text
        self.stack: list[Element] = []
        self.root: Element | None = None

    def parse(self) -> Element:
        try:
            self.parser.Parse(self.data, True)
        except expat.ExpatError as e:
            if e.code == expat.errors.codes[expat.errors.XML_ERROR_INVALID_TOKEN]:
                from mlaunch.frontends.encoding import not_utf8  # error path only

                # expat says "invalid token" for bytes that are not in the file's encoding
                raise not_utf8(self.data, self.path) or self.expat_error(e)
            raise self.expat_error(e)
        if self.root is None:  # expat reports a missing root itself; kept for type safety
            raise LaunchFileError("no <launch> element", where=self.path)
        return self.root

    def expat_error(self, e: expat.ExpatError) -> LaunchFileError:
        where = f"{self.path}:{e.lineno}:{e.offset + 1}"
        return LaunchFileError(f"malformed XML: {expat.ErrorString(e.code)}", where=where)

    def start(self, tag: str, attributes: dict[str, str]) -> None:
        p = self.parser
        line, col = p.CurrentLineNumber, p.CurrentColumnNumber + 1
        if len(self.stack) >= DEPTH_LIMIT:
            raise too_deep(f"{self.path}:{line}:{col}", "XML elements")
        e = Element(tag=tag, path=self.path, line=line, col=col, fmt="xml")
        index = p.CurrentByteIndex
        for name, value in attributes.items():
            e.attrs[name] = Attr(value, line, col, partial(self.locate, index, line, col, name))
        if self.stack:
            parent = self.stack[-1]
            if parent.children is None:
                parent.children = []
            parent.children.append(e)
        else:
            self.root = e
        self.stack.append(e)

    def end(self, tag: str) -> None:
        self.stack.pop()

    def text(self, data: str) -> None:
        if data.strip() and self.stack:
            e = self.stack[-1]
            p = self.parser
            raise LaunchFileError(
                f"unexpected text {data.strip()!r} inside {e.what} (values go in attributes)",
                where=f"{self.path}:{p.CurrentLineNumber}:{p.CurrentColumnNumber + 1}",
                what=e.what,
            )

    def locate(self, index: int, line: int, col: int, name: str) -> tuple[int, int]:
        """Where the value of attribute ``name`` of the start tag at ``index`` begins."""
        return self.value_positions(index, line, col).get(name, (line, col))

    def value_positions(self, index: int, line: int, col: int) -> dict[str, tuple[int, int]]:
        """Line and column where each attribute value of the start tag at ``index`` begins."""
        data = self.data
        i = index + 1
        while i < len(data) and data[i : i + 1] not in b" \t\r\n/>":
            i += 1
        out: dict[str, tuple[int, int]] = {}
        while True:
            m = _ATTRIBUTE.match(data, i)
            if m is None:
                return out
            start = m.end()
            end = data.find(m.group(2), start)
            if end < 0:
                return out
            out[m.group(1).decode("utf-8", "replace")] = _advance(data, index, start, line, col)
            i = end + 1


def _advance(data: bytes, frm: int, to: int, line: int, col: int) -> tuple[int, int]:
    """The position of byte ``to`` given that byte ``frm`` is at (line, col)."""
    chunk = data[frm:to].decode("utf-8", "replace")
    newlines = chunk.count("\n")
    if newlines:
        return line + newlines, len(chunk) - chunk.rfind("\n")
    return line, col + len(chunk)
