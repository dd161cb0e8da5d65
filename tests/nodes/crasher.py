#!/usr/bin/env python3
"""A ROS node that crashes (status 1) S seconds after its process started, however long rclpy
took to start: the node of the smoke runs' crash variant (tests/launches/jtbot_crash.launch.py).

    python crasher.py --crash-after S [--ros-args ...]
"""

from __future__ import annotations

import time

STARTED = time.monotonic()  # first, before the imports that take a loaded machine a while

import argparse  # noqa: E402
from typing import Any  # noqa: E402

from _ros_main import StopNode, main, split_args  # noqa: E402


def build(argv: list[str]) -> Any:
    from rclpy.node import Node

    parser = argparse.ArgumentParser(prog="crasher.py", description=__doc__.splitlines()[0])
    parser.add_argument("--crash-after", type=float, required=True, metavar="SECONDS")
    options = split_args(parser, argv)
    node = Node("crasher")

    def crash() -> None:
        took = time.monotonic() - STARTED
        node.get_logger().error(
            f"crashing {took:.1f} s after start (asked: {options.crash_after} s)"
        )
        raise StopNode(1)

    left = options.crash_after - (time.monotonic() - STARTED)
    node.create_timer(max(0.001, left), crash)
    return node


if __name__ == "__main__":
    main(build)
