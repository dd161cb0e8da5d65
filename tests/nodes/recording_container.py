#!/usr/bin/env python3
"""Test container: answers ``~/_container/load_node`` with success and prints each request.

    python recording_container.py [--fail PLUGIN] [--exit-on PLUGIN]
                                  [--ros-args -r __node:=NAME -r __ns:=NS ...]

Each LoadNode request is one JSON line on stdout (its fields; parameters and extra arguments as
[name, type, value]), so a test compares what a launcher sent with what it expects. ``--fail``
answers success=false with the message 'refused by the recording container' for that plugin.
``--exit-on`` makes the container die (status 3) on a request for that plugin, after printing
it and before answering: a container that dies while a load is in flight.
"""

from __future__ import annotations

import json
import os
import sys
from typing import Any

import rclpy
from composition_interfaces.srv import LoadNode
from rclpy.node import Node

from mlaunch.launch_ros.load_request import from_message


def as_json(msg: Any) -> str:
    request = from_message(msg)
    out = {name: getattr(request, name) for name in request._fields}
    for key in ("parameters", "extra_arguments"):
        out[key] = [[p.name, p.type, p.value] for p in out[key]]
    return json.dumps(out)


def main() -> int:
    args = rclpy.utilities.remove_ros_args(sys.argv)[1:]
    fail = args[args.index("--fail") + 1] if "--fail" in args else None
    exit_on = args[args.index("--exit-on") + 1] if "--exit-on" in args else None
    rclpy.init()
    node = Node("recording_container")
    count = 0

    def on_load(request: Any, response: Any) -> Any:
        nonlocal count
        print(as_json(request), flush=True)
        if request.plugin_name == exit_on:
            os._exit(3)  # no answer, no clean-up: the request stays in flight
        if request.plugin_name == fail:
            response.success = False
            response.error_message = "refused by the recording container"
            return response
        count += 1
        ns = request.node_namespace or "/"
        name = request.node_name or "unnamed"
        response.success = True
        response.full_node_name = ns.rstrip("/") + "/" + name
        response.unique_id = count
        return response

    node.create_service(LoadNode, "~/_container/load_node", on_load)
    node.get_logger().info("recording container ready")
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
