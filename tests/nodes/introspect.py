#!/usr/bin/env python3
"""Test node that reports how ROS resolved its command line, as one JSON line on stdout.

    python introspect.py [any non-ROS args] [--ros-args -r __ns:=/robot1 -p answer:=42 ...]

Once its node ('introspect' unless renamed), publisher and subscriptions exist, it prints
(flushed) one line:

    {"name": "introspect", "namespace": "/robot1", "fqn": "/robot1/introspect", "pid": 1234,
     "argv": [non-ROS args],
     "parameters": {"answer": {"type": "integer", "value": 42}, "use_sim_time": {...}, ...},
     "resolved": {"chatter": "/robot1/chatter", "~/private": "/robot1/introspect/private",
                  "/absolute": "/absolute"},
     "publishers": ["/robot1/chatter"], "subscriptions": ["/robot1/introspect/private", ...]}

Parameters are declared from the overrides (`-p`, `--params-file`), so every given parameter is
listed; types are rclpy's Parameter.Type names in lower case (bool, integer, double, string,
byte_array, bool_array, integer_array, double_array, string_array). `resolved` is
`node.resolve_topic_name` (remaps applied); publishers/subscriptions are the entities' own
topic names. It then idles until SIGINT/SIGTERM and exits 0.
"""

from __future__ import annotations

import json
import os
from typing import Any

from _ros_main import main

TOPICS = ("chatter", "~/private", "/absolute")


def _plain(value: Any) -> Any:
    """A JSON-ready copy of a parameter value (arrays arrive as array.array or bytes lists)."""
    if isinstance(value, str | bool | int | float) or value is None:
        return value
    return [_plain(item) for item in value]


def _parameters(node: Any) -> dict[str, dict[str, Any]]:
    # depth 0 = recursive: every declared name, dotted ones included.
    names = sorted(node.list_parameters([], 0).names)
    return {
        p.name: {"type": p.type_.name.lower(), "value": _plain(p.value)}
        for p in node.get_parameters(names)
    }


def _report(node: Any, publishers: list[Any], subscriptions: list[Any], argv: list[str]) -> str:
    from rclpy.utilities import remove_ros_args

    return json.dumps(
        {
            "name": node.get_name(),
            "namespace": node.get_namespace(),
            "fqn": node.get_fully_qualified_name(),
            "pid": os.getpid(),
            "argv": remove_ros_args(argv)[1:],
            "parameters": _parameters(node),
            "resolved": {topic: node.resolve_topic_name(topic) for topic in TOPICS},
            "publishers": [p.topic_name for p in publishers],
            "subscriptions": [s.topic_name for s in subscriptions],
        }
    )


def build(argv: list[str]) -> Any:
    from rclpy.node import Node
    from std_msgs.msg import String

    node = Node("introspect", automatically_declare_parameters_from_overrides=True)
    publishers = [node.create_publisher(String, "chatter", 10)]
    subscriptions = [
        node.create_subscription(String, topic, lambda _msg: None, 10) for topic in TOPICS[1:]
    ]
    print(_report(node, publishers, subscriptions, argv), flush=True)
    return node


if __name__ == "__main__":
    main(build)
