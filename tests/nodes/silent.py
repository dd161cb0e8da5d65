#!/usr/bin/env python3
"""Test node 'silent': advertises std_msgs/String on a topic and never publishes on it.

    python silent.py [--topic NAME] [--ros-args ...]

For "the topic exists but nothing ever arrives" tests: the topic (default `silent`, relative to
the node's namespace) shows up in the graph with a publisher, yet no message is ever sent.
SIGINT/SIGTERM end it with status 0.
"""

from __future__ import annotations

import argparse
from typing import Any

from _ros_main import main, split_args


def build(argv: list[str]) -> Any:
    from rclpy.node import Node
    from std_msgs.msg import String

    parser = argparse.ArgumentParser(prog="silent.py", description=__doc__.splitlines()[0])
    parser.add_argument("--topic", default="silent")
    options = split_args(parser, argv)
    node = Node("silent")
    # The node holds on to its publishers, so this one stays advertised; it never publishes.
    node.create_publisher(String, options.topic, 10)
    return node


if __name__ == "__main__":
    main(build)
