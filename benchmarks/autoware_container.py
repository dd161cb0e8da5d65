"""The component container of the Autoware fixture: ``python autoware_container.py ROS_ARGS``.

mlaunch's container stand-in (an rclpy node serving ``~/_container/load_node``, ``unload_node``
and ``list_nodes`` as rclcpp_components' does), told to host every plugin it is asked for as a
bare node with the request's name, namespace, remaps and parameters: the fixture's plugins are
Autoware's C++ components, which are not built here. When ``MLAUNCH_FIXTURE_FIFO`` names a FIFO,
it says there that it runs (``p``, before rclpy is imported, as a recorder does) and each
component it loaded (``l NAME``), so the benchmark sees the moment everything is up.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterator, Mapping
from typing import Any

FIFO_VARIABLE = "MLAUNCH_FIXTURE_FIFO"


def announce(line: str) -> None:
    """One line to the benchmark's FIFO (a single write, shorter than PIPE_BUF), if there is one."""
    fifo = os.environ.get(FIFO_VARIABLE)
    if not fifo:
        return
    fd = os.open(fifo, os.O_WRONLY | os.O_APPEND)
    try:
        os.write(fd, (line[:500] + "\n").encode(errors="replace"))
    finally:
        os.close(fd)


def default_name(plugin: str) -> str:
    """A component's node name when the request names none: its class, as ROS spells names."""
    last = plugin.rsplit("::", 1)[-1] or "component"
    return "".join(c if c.isalnum() else "_" for c in last).lower()


def _loaded(node: Any) -> object:
    announce(f"l {node.get_fully_qualified_name()}")
    return None


class AnyPlugin(Mapping[tuple[str, str], tuple[str, Callable[[Any], object]]]):
    """Every (package, plugin) is hosted: a bare node, announced once made."""

    def __getitem__(self, key: tuple[str, str]) -> tuple[str, Callable[[Any], object]]:
        return default_name(key[1]), _loaded

    def __iter__(self) -> Iterator[tuple[str, str]]:
        return iter(())

    def __len__(self) -> int:
        return 0


if __name__ == "__main__":
    announce(f"p {os.path.basename(sys.argv[0])}")
    from mlaunch.standins import container

    sys.exit(container.main(plugins=AnyPlugin()))
