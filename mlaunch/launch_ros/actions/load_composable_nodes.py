"""``launch_ros.actions.load_composable_nodes``, where upstream defines it, with the request
builder launch_ros's helpers and tests call."""

from __future__ import annotations

from typing import Any

from mlaunch.launch_ros.actions import LoadComposableNodes


def get_composable_node_load_request(composable_node_description: Any, context: Any) -> Any:
    """The ``composition_interfaces`` LoadNode request launch_ros sends for the description in
    ``context`` (the pushed namespace, global remaps and parameters applied); needs the built
    composition_interfaces. A description whose own condition is false has none: ValueError."""
    from mlaunch.launch_ros.load_request import load_request, to_message

    request = load_request(composable_node_description, context)
    if request is None:
        raise ValueError("the composable node's condition is false: it is not loaded")
    return to_message(request)


__all__ = ["LoadComposableNodes", "get_composable_node_load_request"]
