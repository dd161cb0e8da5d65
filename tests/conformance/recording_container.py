"""The conformance suite's component container: records every LoadNode request it is sent.

Installed as ``lib/conf_pkg/recording_container`` (see components.py), so a launch file starts it
as ``ComposableNodeContainer(package='conf_pkg', executable='recording_container', ...)`` or as a
plain Node that a LoadComposableNodes elsewhere targets. It serves ``~/_container/load_node`` and
appends each request, whole, as one JSON line to ``$CONF_RECORD_DIR/loads.jsonl``: the
container's full name, then every field of the request (parameters and extra arguments with
their ParameterType and the value of that type). It answers success with a full node name that
is unique within the container (``namespace/name``, or ``/unnamed_N`` without a name) unless the
plugin is named by ``--fail PLUGIN`` (repeatable): then success is false with the error message
``recording container refuses PLUGIN``. With ``--echo-names`` the full name is ``namespace/name``
even when it was given before (as rclcpp's containers do), so a launcher's count of node names
shows.

It imports only rclpy and composition_interfaces, never mlaunch: it is the witness, the same
under either launcher.
"""

import json
import os
import sys

import rclpy
from composition_interfaces.srv import LoadNode
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

# rcl_interfaces/msg/ParameterType -> the ParameterValue field that carries the value.
VALUE_FIELDS = {
    1: "bool_value",
    2: "integer_value",
    3: "double_value",
    4: "string_value",
    5: "byte_array_value",
    6: "bool_array_value",
    7: "integer_array_value",
    8: "double_array_value",
    9: "string_array_value",
}


def parameter(p):
    """[name, type, value] of one rcl_interfaces/Parameter (arrays as lists, bytes as ints)."""
    field = VALUE_FIELDS.get(p.value.type)
    if field is None:
        return [p.name, p.value.type, None]
    value = getattr(p.value, field)
    if p.value.type == 5:
        value = [b[0] if isinstance(b, bytes) else int(b) for b in value]
    elif p.value.type > 5:
        value = list(value)
    return [p.name, p.value.type, value]


def as_record(container, request):
    return {
        "container": container,
        "package_name": request.package_name,
        "plugin_name": request.plugin_name,
        "node_name": request.node_name,
        "node_namespace": request.node_namespace,
        "log_level": request.log_level,
        "remap_rules": list(request.remap_rules),
        "parameters": [parameter(p) for p in request.parameters],
        "extra_arguments": [parameter(p) for p in request.extra_arguments],
    }


def main():
    args = rclpy.utilities.remove_ros_args(sys.argv)[1:]
    refused = {args[i + 1] for i, a in enumerate(args[:-1]) if a == "--fail"}
    echo_names = "--echo-names" in args
    records = os.path.join(os.environ["CONF_RECORD_DIR"], "loads.jsonl")
    rclpy.init(args=sys.argv)
    node = Node("recording_container")
    container = node.get_fully_qualified_name()
    given = []  # the full names answered, in order

    def on_load(request, response):
        line = (json.dumps(as_record(container, request), sort_keys=True) + "\n").encode()
        # One write per line in append mode: lines from several containers never interleave.
        fd = os.open(records, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        os.write(fd, line)
        os.close(fd)
        if request.plugin_name in refused:
            response.success = False
            response.error_message = f"recording container refuses {request.plugin_name}"
            return response
        namespace = (request.node_namespace or "/").rstrip("/")
        name = f"{namespace}/{request.node_name or 'unnamed'}"
        full, n = name, 1
        while full in given and not echo_names:
            n += 1
            full = f"{name}_{n}"
        given.append(full)
        response.success = True
        response.full_node_name = full
        response.unique_id = len(given)
        return response

    node.create_service(LoadNode, "~/_container/load_node", on_load)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
