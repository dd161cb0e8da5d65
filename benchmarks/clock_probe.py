"""Real-time factor of a running simulation, from /clock against the wall clock (needs rclpy).

Usage: python clock_probe.py SECONDS [--wait-topic NAME] [--topic-timeout S] [--timeout S]

Waits for the first /clock message and, with --wait-topic, up to --topic-timeout seconds for a
publisher of that topic (the spawned robot's scan: a robot in the world is the real load), then
prints ``window robot=1`` or ``window robot=0`` (so the harness can start its CPU sample), then
records every /clock message for SECONDS of wall time and prints one JSON line: first and last
(wall, sim) pairs and the message count. Exit 1 with a one-line reason when nothing arrives.
Run it in the simulation's private ROS domain (ROS_DOMAIN_ID, localhost discovery).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="clock_probe.py")
    parser.add_argument("seconds", type=float)
    parser.add_argument("--wait-topic", default=None)
    parser.add_argument("--topic-timeout", type=float, default=20.0)
    parser.add_argument("--timeout", type=float, default=60.0)
    args = parser.parse_args(argv)

    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    rclpy.init()
    node = rclpy.create_node("mlaunch_bench_clock_probe")
    samples: list[tuple[float, float]] = []

    def on_clock(msg: Any) -> None:
        samples.append((time.monotonic(), msg.clock.sec + msg.clock.nanosec * 1e-9))

    qos = QoSProfile(depth=50, reliability=ReliabilityPolicy.BEST_EFFORT)
    node.create_subscription(Clock, "/clock", on_clock, qos)
    try:
        deadline = time.monotonic() + args.timeout
        while not samples:
            if time.monotonic() > deadline:
                print(f"clock_probe: no /clock within {args.timeout:g} s", file=sys.stderr)
                return 1
            rclpy.spin_once(node, timeout_sec=0.1)
        robot = not args.wait_topic
        deadline = time.monotonic() + args.topic_timeout
        while not robot and time.monotonic() < deadline:
            robot = _has_publisher(node, args.wait_topic)
            rclpy.spin_once(node, timeout_sec=0.1)
        samples.clear()
        print(f"window robot={int(robot)}", flush=True)
        end = time.monotonic() + args.seconds
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)
        if len(samples) < 2:
            print("clock_probe: /clock stopped during the window", file=sys.stderr)
            return 1
        (w0, s0), (w1, s1) = samples[0], samples[-1]
        result = {"wall0": w0, "wall1": w1, "sim0": s0, "sim1": s1, "messages": len(samples)}
        print(json.dumps(result), flush=True)
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def _has_publisher(node: Any, topic: str) -> bool:
    return bool(node.count_publishers(topic))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
