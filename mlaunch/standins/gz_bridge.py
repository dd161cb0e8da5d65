"""Stand-in for ros_gz_bridge's ``parameter_bridge`` and ``bridge_node``, and ros_gz_image's
``image_bridge``: ``python -m mlaunch.standins.gz_bridge PROGRAM ARGS...``.

The simulator stand-in serves the Gazebo topics of its models (a diff drive's ``cmd_vel`` and
``odom``, a lidar's ``scan``, ``/clock`` ...) on ROS directly, under their gz names, as if they
were bridged one to one. So a bridge whose ROS name is the gz name has nothing to carry; this
stand-in reads and checks the same bridges the real programs take (``TOPIC@ROS_TYPE@GZ_TYPE``
with ``@``, ``[`` or ``]`` for the direction, and the ``config_file`` parameter's YAML list),
says what it bridges, relays the topics whose ROS name differs from the gz name, and tells the
simulator which ROS type a bridged topic has (``geometry_msgs/msg/TwistStamped`` on cmd_vel)
through ``/mlaunch_sim/bridges``. rclpy is imported inside main() only.
"""

from __future__ import annotations

import importlib
import json
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from mlaunch.plan.errors import StandinError
from mlaunch.standins.common import EXIT_FAILURE, init_ros, latched, spin_until_shutdown

PROGRAMS = ("parameter_bridge", "bridge_node", "image_bridge")
DIRECTIONS = ("BIDIRECTIONAL", "GZ_TO_ROS", "ROS_TO_GZ")
# The spec's separator -> its direction (ros_gz_bridge's README: @ both ways, [ gz to ROS,
# ] ROS to gz).
SEPARATORS = {"@": "BIDIRECTIONAL", "[": "GZ_TO_ROS", "]": "ROS_TO_GZ"}
CONFIG_KEYS = frozenset(
    {
        "topic_name",
        "ros_topic_name",
        "gz_topic_name",
        "ros_type_name",
        "gz_type_name",
        "direction",
        "lazy",
        "subscriber_queue",
        "publisher_queue",
        "qos_profile",
    }
)
BRIDGES_TOPIC = "/mlaunch_sim/bridges"
# A bridge list is a few dozen lines; a bound keeps an alias bomb from reaching the parser.
MAX_CONFIG_BYTES = 1 << 20
PROG = "gz_bridge"


class BridgeError(StandinError):
    """A bridge the real program would refuse: the message names it and what is valid."""


@dataclass(frozen=True)
class Bridge:
    """One bridged topic: its ROS and gz names and types, and which way messages go."""

    ros_topic: str
    gz_topic: str
    ros_type: str
    gz_type: str
    direction: str

    def describe(self) -> str:
        arrow = {"BIDIRECTIONAL": "<->", "GZ_TO_ROS": "<-", "ROS_TO_GZ": "->"}[self.direction]
        return f"{self.ros_topic} ({self.ros_type}) {arrow} gz {self.gz_topic} ({self.gz_type})"


def parse_spec(text: str) -> Bridge:
    """``TOPIC@ROS_TYPE@GZ_TYPE`` (``[`` or ``]`` for one way) as parameter_bridge reads it."""
    at = text.find("@")
    if at <= 0:
        raise BridgeError(
            f"bridge {text!r}: expected TOPIC@ROS_TYPE@GZ_TYPE (or [GZ_TYPE for gz to ROS,"
            " ]GZ_TYPE for ROS to gz)"
        )
    topic, rest = text[:at], text[at + 1 :]
    cut = max(rest.rfind(s) for s in SEPARATORS)
    if cut <= 0 or cut == len(rest) - 1:
        raise BridgeError(
            f"bridge {text!r}: expected TOPIC@ROS_TYPE@GZ_TYPE, with ROS_TYPE like"
            " std_msgs/msg/String and GZ_TYPE like gz.msgs.StringMsg"
        )
    ros_type, gz_type = rest[:cut], rest[cut + 1 :]
    return Bridge(topic, topic, check_ros_type(ros_type, text), gz_type, SEPARATORS[rest[cut]])


def check_ros_type(name: str, where: str) -> str:
    """A ROS type as ``pkg/msg/Type`` (``pkg/Type`` is read as a message too, as rosidl does)."""
    parts = name.split("/")
    if len(parts) == 2:
        parts = [parts[0], "msg", parts[1]]
    if len(parts) != 3 or parts[1] != "msg" or not all(p.isidentifier() for p in parts):
        raise BridgeError(
            f"{where}: ROS type {name!r} is not a message type like nav_msgs/msg/Odometry"
        )
    return "/".join(parts)


def parse_config(text: str, path: str) -> list[Bridge]:
    """The ``config_file`` YAML: a list of bridges, each a mapping of ros_gz_bridge's keys."""
    import yaml  # only when there is a config to read

    from mlaunch.plan.yamldata import YamlLimitError
    from mlaunch.plan.yamldata import load as load_yaml

    if len(text) > MAX_CONFIG_BYTES:
        raise BridgeError(f"config_file {path!r} is over {MAX_CONFIG_BYTES} bytes")
    try:
        data = load_yaml(text, path)
    except YamlLimitError as exc:
        raise BridgeError(f"config_file {exc}") from None
    except yaml.YAMLError as exc:
        raise BridgeError(f"config_file {path!r} is not valid YAML: {exc}") from None
    if data is None:
        return []
    if not isinstance(data, list):
        kind = type(data).__name__
        raise BridgeError(f"config_file {path!r}: expected a list of bridges, got a {kind}")
    return [_config_entry(entry, f"{path}: bridge {n}") for n, entry in enumerate(data, 1)]


def _config_entry(entry: object, where: str) -> Bridge:
    if not isinstance(entry, dict):
        raise BridgeError(f"{where}: expected a mapping of ros_topic_name, gz_topic_name, ...")
    unknown = sorted(str(k) for k in entry if k not in CONFIG_KEYS)
    if unknown:
        raise BridgeError(
            f"{where}: unknown key {unknown[0]!r} (valid: {', '.join(sorted(CONFIG_KEYS))})"
        )
    common = entry.get("topic_name")
    ros_topic = entry.get("ros_topic_name", common)
    gz_topic = entry.get("gz_topic_name", common)
    if not ros_topic or not gz_topic:
        raise BridgeError(f"{where}: needs topic_name, or both ros_topic_name and gz_topic_name")
    for key in ("ros_type_name", "gz_type_name"):
        if not entry.get(key):
            raise BridgeError(f"{where}: needs {key}")
    direction = str(entry.get("direction", "BIDIRECTIONAL"))
    if direction not in DIRECTIONS:
        raise BridgeError(f"{where}: direction {direction!r} is not one of {', '.join(DIRECTIONS)}")
    ros_type = check_ros_type(str(entry["ros_type_name"]), where)
    return Bridge(str(ros_topic), str(gz_topic), ros_type, str(entry["gz_type_name"]), direction)


def image_bridges(topics: Sequence[str]) -> list[Bridge]:
    """image_bridge TOPIC...: each gz image topic to sensor_msgs/msg/Image under its own name."""
    return [Bridge(t, t, "sensor_msgs/msg/Image", "gz.msgs.Image", "GZ_TO_ROS") for t in topics]


def gz_name(topic: str, namespace: str = "") -> str:
    """A gz topic as the simulator stand-in serves it on ROS: absolute, one slash between parts."""
    parts = [p for p in f"{namespace}/{topic}".split("/") if p]
    return "/" + "/".join(parts)


def message_class(ros_type: str) -> Any:
    """The Python class of ``pkg/msg/Type``; a BridgeError naming the package when it is missing."""
    package, _, name = ros_type.split("/")
    try:
        return getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError):
        raise BridgeError(
            f"ROS type {ros_type!r}: package {package!r} has no message {name!r} here"
            " (not installed in this Python environment)"
        ) from None


# ---------------------------------------------------------------- the node


def main(argv: Sequence[str] | None = None) -> int:
    """Bridge until shutdown; 1 with one line when a bridge or the config is unusable."""
    args = list(sys.argv[1:] if argv is None else argv)
    program = args.pop(0) if args and args[0] in PROGRAMS else "parameter_bridge"
    try:
        return _run(program, args)
    except BridgeError as exc:
        print(f"[ERROR] [{program}]: {exc}", file=sys.stderr, flush=True)
        return EXIT_FAILURE


def _run(program: str, args: list[str]) -> int:
    from rclpy.node import Node
    from rclpy.utilities import remove_ros_args

    plain = remove_ros_args(["x", *args])[1:]
    bridges = image_bridges(plain) if program == "image_bridge" else [parse_spec(w) for w in plain]
    stop = init_ros(["x", *args], program)
    if stop is None:
        return EXIT_FAILURE
    node = Node("ros_gz_image" if program == "image_bridge" else "ros_gz_bridge")
    return spin_until_shutdown(node, lambda: _start(node, bridges), {BridgeError: ""}, stop)


def _start(node: Any, bridges: list[Bridge]) -> None:
    from std_msgs.msg import String

    config = node.declare_parameter("config_file", "").value
    if config:
        bridges = [*bridges, *_read_config(str(config))]
    if not bridges:
        raise BridgeError("no bridge: give TOPIC@ROS_TYPE@GZ_TYPE or the config_file parameter")
    # As the real bridge: gz names are global unless this asks to put them in the namespace.
    expand = node.declare_parameter("expand_gz_topic_names", False).value
    prefix = node.get_namespace() if expand is True else ""
    announced = []
    for bridge in bridges:
        ros = node.resolve_topic_name(bridge.ros_topic)
        gz = gz_name(bridge.gz_topic, prefix)
        announced.append({"gz_topic": gz, "ros_topic": ros, "ros_type": bridge.ros_type})
        _bridge(node, bridge, ros, gz)
    note = {"node": node.get_fully_qualified_name(), "bridges": announced}
    node.create_publisher(String, BRIDGES_TOPIC, latched()).publish(String(data=json.dumps(note)))


def _read_config(path: str) -> list[Bridge]:
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as exc:
        raise BridgeError(f"config_file {path!r} cannot be read: {exc.strerror}") from None
    return parse_config(text, path)


def _bridge(node: Any, bridge: Bridge, ros: str, gz: str) -> None:
    """Say the bridge, and relay it where the ROS name is not the name the simulator serves."""
    if ros == gz:
        print(f"{PROG}: {bridge.describe()}: served by the simulator stand-in", flush=True)
        return
    try:
        msg_type = message_class(bridge.ros_type)
    except BridgeError as exc:
        print(f"{PROG}: cannot bridge {bridge.describe()}: {exc}", file=sys.stderr, flush=True)
        return
    if bridge.direction == "ROS_TO_GZ":
        source, target = ros, gz
    else:  # gz to ROS, and one way only for both ways: a relay back would echo every message
        source, target = gz, ros
    publisher = node.create_publisher(msg_type, target, 10)
    node.create_subscription(msg_type, source, publisher.publish, 10)
    print(f"{PROG}: {bridge.describe()}: relayed {source} -> {target}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
