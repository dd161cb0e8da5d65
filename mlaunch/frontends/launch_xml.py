"""ROS 2's ``launch_xml``: the XML implementation of ``launch.frontend`` (Parser, Entity),
served by mlaunch's located XML reader. mlaunch registers it as the entry point ``xml`` of
``mlaunch.frontend.parser``.
"""

from __future__ import annotations

from mlaunch.frontends import xml
from mlaunch.frontends.markup import MarkupEntity, MarkupParser
from mlaunch.launch import launch_description_sources


class Entity(MarkupEntity):
    """One element of an XML launch file: attributes are text, coerced to the type asked for
    (``name-sep`` splits a list)."""


class Parser(MarkupParser):
    """The XML parser implementation."""

    entity_class = Entity
    reader = staticmethod(xml.parse_root)
    extensions = frozenset({"launch.xml", "xml", "launch"})


__all__ = ["Entity", "Parser", "launch_description_sources"]
