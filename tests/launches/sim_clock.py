#!/usr/bin/env python3
"""Publishes rosgraph_msgs/Clock on /clock at 50 Hz, as a simulator would.

    python sim_clock.py [--frozen] [--ros-args ...]

Simulated time starts at 100 s and advances 20 ms per message, or stays at 100 s with
--frozen (a paused simulator). SIGINT/SIGTERM end it with status 0.
"""

from __future__ import annotations

import signal
import sys


def main() -> int:
    import rclpy
    from rclpy.clock import Clock as RosClock
    from rclpy.clock import ClockType
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.utilities import remove_ros_args
    from rosgraph_msgs.msg import Clock

    frozen = "--frozen" in remove_ros_args(sys.argv)[1:]
    rclpy.init(args=sys.argv)
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
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(0)
