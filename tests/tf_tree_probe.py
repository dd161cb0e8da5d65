"""Listens to a running robot's TF like a tf2 listener would; prints one JSON line.

Subscribes to robot_description (latched), /tf_static (latched) and /tf, and waits, with a
deadline, until every link of the URDF is reachable from the root frame given as argv[1]
(``odom`` for a simulated robot) through the transforms seen. Prints the frames seen, each
child's parent and pose, and what is missing if the deadline passes (exit status 3).
"""

from __future__ import annotations

import json
import sys
import time


def reachable(root: str, parents: dict[str, str], frame: str) -> bool:
    """Whether following parents up from ``frame`` arrives at ``root``."""
    seen: set[str] = set()
    while frame != root:
        if frame in seen or frame not in parents:
            return False
        seen.add(frame)
        frame = parents[frame]
    return True


def main() -> int:
    import rclpy
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String
    from tf2_msgs.msg import TFMessage

    from mlaunch.standins.urdf import parse_urdf

    root, deadline_s = sys.argv[1], float(sys.argv[2])
    rclpy.init()
    node = rclpy.create_node("tf_tree_probe")
    latched = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    parents: dict[str, str] = {}
    topics: dict[str, str] = {}
    poses: dict[str, list[float]] = {}  # child -> x y z qx qy qz qw, rounded
    links: list[str] = []

    def keep(topic: str):  # type: ignore[no-untyped-def]
        def on(msg: TFMessage) -> None:
            for t in msg.transforms:
                parents[t.child_frame_id] = t.header.frame_id
                topics[t.child_frame_id] = topic
                move, turn = t.transform.translation, t.transform.rotation
                values = (move.x, move.y, move.z, turn.x, turn.y, turn.z, turn.w)
                poses[t.child_frame_id] = [round(v, 6) + 0.0 for v in values]

        return on

    node.create_subscription(TFMessage, "/tf_static", keep("/tf_static"), latched)
    node.create_subscription(TFMessage, "/tf", keep("/tf"), 100)

    def on_description(msg: String) -> None:
        links.extend(parse_urdf(msg.data).links)

    node.create_subscription(String, "robot_description", on_description, latched)
    deadline = time.monotonic() + deadline_s
    while not (links and all(reachable(root, parents, link) for link in links)):
        if time.monotonic() > deadline:
            missing = [link for link in links if not reachable(root, parents, link)]
            print(json.dumps({"error": "timeout", "links": links, "missing": missing,
                              "parents": parents}))  # fmt: skip
            return 3
        rclpy.spin_once(node, timeout_sec=0.05)
    print(json.dumps({"links": links, "parents": parents, "topics": topics, "poses": poses}))
    node.destroy_node()
    rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
