#!/usr/bin/env python3
"""Test talker: publishes std_msgs/String 'Hello World: N' on `chatter` at the `rate` parameter.

    python talker.py [--die-after S [--exit-code N]] [--count N] [--best-effort | --latched]
                     [--ros-args -p rate:=20.0 -r __ns:=/robot1 ...]

- `rate` (Hz, default 10, int or float) sets the publish rate.
- `--die-after S` ends the program S seconds after start with status `--exit-code` (default 1),
  to test crash handling; SIGINT/SIGTERM still end it with 0.
- `--count N` stops publishing after N messages (the node stays up).
- `--slow-teardown S` takes S seconds to tear down after a stop signal, as a middleware whose
  teardown hangs does (a second signal must still end it).
- `--best-effort` publishes with BEST_EFFORT reliability; `--latched` with TRANSIENT_LOCAL
  durability (a late subscriber still gets the last message).
Each message is also logged at INFO (stderr), like demo_nodes_py's talker.
"""

from __future__ import annotations

import argparse
from typing import Any

from _ros_main import StopNode, main, split_args


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="talker.py", description=__doc__.splitlines()[0])
    parser.add_argument("--die-after", type=float, metavar="SECONDS")
    parser.add_argument("--exit-code", type=int, metavar="N")
    parser.add_argument("--count", type=int, metavar="N")
    parser.add_argument("--slow-teardown", type=float, metavar="SECONDS")
    qos = parser.add_mutually_exclusive_group()
    qos.add_argument("--best-effort", action="store_true")
    qos.add_argument("--latched", action="store_true")
    return parser


def _qos(options: argparse.Namespace) -> Any:
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    profile = QoSProfile(depth=10)
    if options.best_effort:
        profile.reliability = ReliabilityPolicy.BEST_EFFORT
    if options.latched:
        profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return profile


def build(argv: list[str]) -> Any:
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.node import Node
    from std_msgs.msg import String

    parser = _parser()
    options = split_args(parser, argv)
    if options.exit_code is not None and options.die_after is None:
        parser.error("--exit-code N needs --die-after SECONDS (it is the status of that exit)")
    node = Node("talker")
    # dynamic_typing: `-p rate:=20` (an integer) and `-p rate:=20.0` are both fine.
    rate = node.declare_parameter("rate", 10.0, ParameterDescriptor(dynamic_typing=True)).value
    if not isinstance(rate, int | float) or isinstance(rate, bool) or rate <= 0:
        parser.error(f"parameter rate must be a positive number of Hz, got {rate!r}")
    publisher = node.create_publisher(String, "chatter", _qos(options))
    sent = 0

    def publish() -> None:
        nonlocal sent
        if options.count is not None and sent >= options.count:
            return
        sent += 1
        publisher.publish(String(data=f"Hello World: {sent}"))
        node.get_logger().info(f'Publishing: "Hello World: {sent}"')

    def die() -> None:
        node.get_logger().info(f"dying after {options.die_after} s as asked")
        raise StopNode(1 if options.exit_code is None else options.exit_code)

    node.create_timer(1.0 / float(rate), publish)
    if options.die_after is not None:
        node.create_timer(options.die_after, die)
    if options.slow_teardown is not None:
        _slow_teardown(node, options.slow_teardown)
    return node


def _slow_teardown(node: Any, seconds: float) -> None:
    """Make destroying ``node`` take ``seconds`` first (signals are only recorded meanwhile)."""
    import time

    destroy = node.destroy_node

    def slow() -> None:
        node.get_logger().info(f"tearing down for {seconds} s")
        time.sleep(seconds)
        destroy()

    node.destroy_node = slow


if __name__ == "__main__":
    main(build)
