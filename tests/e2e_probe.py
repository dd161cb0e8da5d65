"""Checks a running jtbot simulation from outside, as a user would; prints one JSON line.

Run in the same ROS domain as the launch: waits for the nodes, reads use_sim_time from every
node's parameter service, checks that /clock advances, drives the robot with /cmd_vel and
compares /odom and /scan before and after. Every wait has a deadline.
"""

from __future__ import annotations

import json
import math
import sys
import time


def main() -> int:
    import rclpy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rcl_interfaces.srv import GetParameters
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import LaserScan

    expected = sys.argv[1].split(",")
    deadline_s = float(sys.argv[2]) if len(sys.argv) > 2 else 30.0
    rclpy.init()
    node = rclpy.create_node("e2e_probe")
    result: dict[str, object] = {}
    latest: dict[str, object] = {}
    best_effort = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
    node.create_subscription(Clock, "/clock", lambda m: latest.__setitem__("clock", m), best_effort)
    node.create_subscription(
        Odometry, "/odom", lambda m: latest.__setitem__("odom", m), best_effort
    )
    node.create_subscription(
        LaserScan, "/scan", lambda m: latest.__setitem__("scan", m), best_effort
    )
    cmd = node.create_publisher(
        Twist,
        "/cmd_vel",
        QoSProfile(
            depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE
        ),
    )
    start = time.monotonic()

    def spin_until(predicate, timeout: float) -> bool:  # type: ignore[no-untyped-def]
        end = min(time.monotonic() + timeout, start + deadline_s)
        while time.monotonic() < end:
            if predicate():
                return True
            rclpy.spin_once(node, timeout_sec=0.05)
        return bool(predicate())

    def names() -> set[str]:
        return {f"{ns.rstrip('/')}/{n}" for n, ns in node.get_node_names_and_namespaces()}

    spin_until(lambda: set(expected) <= names(), 20.0)
    result["nodes"] = sorted(names() - {"/e2e_probe"})
    # use_sim_time of every node, from the node itself.
    sim_time: dict[str, object] = {}
    for fqn in expected:
        client = node.create_client(GetParameters, f"{fqn}/get_parameters")
        if not spin_until(client.service_is_ready, 10.0):
            sim_time[fqn] = "no parameter service"
            continue
        future = client.call_async(GetParameters.Request(names=["use_sim_time"]))
        spin_until(future.done, 5.0)
        values = future.result().values if future.done() and future.result() else []
        sim_time[fqn] = values[0].bool_value if values and values[0].type == 1 else "unset"
    result["use_sim_time"] = sim_time
    # /clock advances.
    spin_until(lambda: "clock" in latest, 10.0)
    first = latest.get("clock")
    t0 = first.clock.sec + first.clock.nanosec * 1e-9 if first else None  # type: ignore[attr-defined]
    spin_until(lambda: latest["clock"] is not first, 5.0) if first else None
    wall = time.monotonic()
    spin_until(lambda: time.monotonic() - wall > 1.0, 2.0)
    last = latest.get("clock")
    t1 = last.clock.sec + last.clock.nanosec * 1e-9 if last else None  # type: ignore[attr-defined]
    result["clock_advanced"] = t0 is not None and t1 is not None and t1 > t0
    result["clock_delta"] = (t1 - t0) if (t0 is not None and t1 is not None) else None
    # Drive: odom and scan before, publish Twist for ~2 s, odom and scan after.
    spin_until(lambda: "odom" in latest and "scan" in latest, 10.0)
    before_odom = latest.get("odom")
    before_scan = latest.get("scan")
    twist = Twist()
    twist.linear.x = 0.4
    twist.angular.z = 0.3
    drive_end = time.monotonic() + 2.0
    while time.monotonic() < drive_end:
        cmd.publish(twist)
        rclpy.spin_once(node, timeout_sec=0.05)
    cmd.publish(Twist())

    # A loaded machine delivers late: wait for a scan taken no earlier than the last odometry
    # of the drive (sim-time stamps), not for a wall-clock delay.
    def stamp(msg: object) -> float:
        header = msg.header  # type: ignore[attr-defined]
        return float(header.stamp.sec + header.stamp.nanosec * 1e-9)

    moved = latest.get("odom")
    spin_until(
        lambda: (
            moved is not None
            and latest.get("scan") is not before_scan
            and stamp(latest["scan"]) >= stamp(moved)
        ),
        10.0,
    )
    after_odom = latest.get("odom")
    after_scan = latest.get("scan")
    if before_odom is not None and after_odom is not None:
        p0, p1 = before_odom.pose.pose.position, after_odom.pose.pose.position  # type: ignore[attr-defined]
        result["odom_moved"] = math.hypot(p1.x - p0.x, p1.y - p0.y)
    if before_scan is not None and after_scan is not None:
        r0, r1 = list(before_scan.ranges), list(after_scan.ranges)  # type: ignore[attr-defined]
        finite = [
            abs(a - b)
            for a, b in zip(r0, r1, strict=False)
            if math.isfinite(a) and math.isfinite(b)
        ]
        result["scan_changed"] = max(finite) if finite else 0.0
        result["scan_samples"] = len(r1)
    print(json.dumps(result), flush=True)
    node.destroy_node()
    rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
