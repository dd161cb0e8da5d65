"""How many nodes of one launch got each name, kept in the context's globals as launch_ros."""

from __future__ import annotations

from typing import Any

from mlaunch.launch_ros.actions.node import node_name_counts


def add_node_name(context: Any, node_name: str) -> None:
    """Count one more node named ``node_name`` in this launch."""
    counts = node_name_counts(context)
    counts[node_name] = counts.get(node_name, 0) + 1


def get_node_name_count(context: Any, node_name: str) -> int:
    """How many nodes named ``node_name`` this launch has made so far."""
    counts = context.locals.get("unique_ros_node_names")
    return 0 if counts is None else int(counts.get(node_name, 0))
