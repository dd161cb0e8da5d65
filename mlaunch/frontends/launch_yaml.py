"""ROS 2's ``launch_yaml``: the YAML implementation of ``launch.frontend`` (Parser, Entity),
served by mlaunch's located YAML reader. mlaunch registers it as the entry point ``yaml`` of
``mlaunch.frontend.parser``.
"""

from __future__ import annotations

from mlaunch.frontends import yaml
from mlaunch.frontends.markup import MarkupEntity, MarkupParser
from mlaunch.launch import launch_description_sources


class Entity(MarkupEntity):
    """One entity of a YAML launch file: values keep their YAML type and are checked against
    the type asked for."""


class Parser(MarkupParser):
    """The YAML parser implementation."""

    entity_class = Entity
    reader = staticmethod(yaml.parse_root)
    extensions = frozenset({"launch.yaml", "launch.yml", "yaml", "yml", "launch"})


__all__ = ["Entity", "Parser", "launch_description_sources"]
