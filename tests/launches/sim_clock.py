#!/usr/bin/env python3
"""Publishes rosgraph_msgs/Clock on /clock at 50 Hz, as a simulator would.

    python sim_clock.py [--frozen] [--ros-args ...]

Simulated time starts at 100 s and advances 20 ms per message, or stays at 100 s with
--frozen (a paused simulator). SIGINT/SIGTERM end it with status 0, whenever they come: it
spins in the test nodes' shared loop (tests/nodes/_ros_main.py). With rclpy's own signal
handlers a SIGINT could shut the context down between two waits of the executor, which then
failed with "RCLError: failed to initialize wait set: the given context is not valid".
"""

from __future__ import annotations

import os
import sys
from typing import Any

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "nodes"))

from _ros_main import main


def build(argv: list[str]) -> Any:
    from rclpy.clock import Clock as RosClock
    from rclpy.clock import ClockType
    from rclpy.node import Node
    from rclpy.utilities import remove_ros_args
    from rosgraph_msgs.msg import Clock

    frozen = "--frozen" in remove_ros_args(argv)[1:]
    node = Node("sim_clock")
    publisher = node.create_publisher(Clock, "/clock", 10)
    now = [100 * 10**9]

    def tick() -> None:
        if not frozen:
            now[0] += 20_000_000
        message = Clock()
        message.clock.sec, message.clock.nanosec = divmod(now[0], 10**9)
        publisher.publish(message)

    # A wall-clock timer: with use_sim_time the node's own clock would wait for /clock forever.
    node.create_timer(0.02, tick, clock=RosClock(clock_type=ClockType.STEADY_TIME))
    return node


if __name__ == "__main__":
    main(build)
